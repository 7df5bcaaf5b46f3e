#pragma once
// Height along the unobservable axis from the ground planes (thesis 3.4.3.1).
// Under planar motion hand-eye leaves the translation along the rotation axis
// at 0. Per frame: RANSAC the ground plane of the base scan and of the target
// scan moved into the base frame by the current X; the shift along the axis
// that puts the target's ground inliers' centroid on the base's ground plane
// is that frame's correction (the thesis's mean of (c_a - R c_b)_z, taken as a
// point-to-plane distance so the two centroids need not be the same ground
// spot). The median over frames is applied.
#include <optional>
#include <span>
#include <vector>

#include "mlidar/core/se3.hpp"
#include "mlidar/core/types.hpp"
#include "mlidar/geometry/plane_ransac.hpp"

namespace mlidar::calib {

struct GroundHeightConfig {
  PlaneRansacConfig ransac{
      .inlier_distance = 0.05, .max_iterations = 300, .min_inliers = 200, .max_planes = 3, .refine_passes = 2, .seed = 1};
  double max_range_m = 30.0;   ///< points farther from their sensor are ignored
  double max_tilt_deg = 15.0;  ///< ground normal within this of the axis
};

/// One frame's shift s (metres) so that X' = (R, t + s axis) puts the target's
/// ground on the base's; nullopt when either ground plane is not found.
std::optional<double> ground_height_shift(const Scan& scan_a, const Scan& scan_b, const SE3& T_a_b, const Vec3& axis_a,
                                          const GroundHeightConfig& config = {});

struct GroundHeightResult {
  SE3 T_a_b;  ///< with the median shift applied (unchanged when no frame worked)
  std::size_t frames_used = 0;
  double shift_m = 0.0;   ///< median shift applied
  double spread_m = 0.0;  ///< median absolute deviation of the shifts x 1.4826
};

/// Frames paired by index (scans_a[i] with scans_b[i]); throws std::invalid_argument when the sizes differ.
GroundHeightResult height_from_ground(std::span<const Scan> scans_a, std::span<const Scan> scans_b, const SE3& T_a_b, const Vec3& axis_a,
                                      const GroundHeightConfig& config = {});

}  // namespace mlidar::calib
