#pragma once
// Aligning an estimated trajectory to the ground truth before the absolute
// error is taken, as evo does (evo/core/geometry.py umeyama_alignment and
// trajectory.align / align_origin).
#include <cstdint>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"

namespace mlidar::eval {

enum class AlignMode : std::uint8_t {
  kNone,    ///< compare as given
  kOrigin,  ///< move the estimate so its first pose equals the ground truth's first pose
  kSe3,     ///< least-squares rotation + translation of the positions (Horn / Umeyama without scale)
  kSim3,    ///< least-squares rotation + translation + scale (Umeyama)
};

/// "none", "origin", "se3", "sim3".
const char* align_mode_name(AlignMode mode);

/// p_gt ~= scale * (R p_est) + t, with T_gt_est = (R, t).
struct Alignment {
  AlignMode mode = AlignMode::kNone;
  SE3 T_gt_est;
  double scale = 1.0;

  /// Applies the alignment to a pose of the estimate: rotation R R_est, translation s R t_est + t.
  SE3 apply(const SE3& T_world_est) const;
};

/// Umeyama (1991), "Least-squares estimation of transformation parameters
/// between two point patterns", eqs 34-43: minimises
/// sum_i |dst_i - (s R src_i + t)|^2; with_scale = false fixes s = 1 (the
/// same optimum as Horn's closed form). Throws InputError(source, "positions")
/// when fewer than 3 points are given or src does not spread (s undefined).
Alignment umeyama_alignment(const std::vector<Vec3>& src, const std::vector<Vec3>& dst, bool with_scale, const std::string& source);

/// The alignment of `mode` that maps est onto gt (pose sequences of equal length, already associated).
Alignment compute_alignment(AlignMode mode, const std::vector<SE3>& gt, const std::vector<SE3>& est, const std::string& source);

}  // namespace mlidar::eval
