#pragma once
// PS-Calib: T_ref_target of two LiDARs that both see a wall corner, from one
// scan each (thesis Chap. 2), read as the paper's pipeline:
//   planes (sequential RANSAC, eq 2.1-2.2) -> corner triple, point, signs,
//   order (eq 2.3-2.5) -> closed form (eq 2.6-2.7) -> refinement (eq 2.8)
//   -> covariance and verdict.
#include <array>
#include <optional>
#include <span>
#include <string>

#include "mlidar/calib/corner.hpp"
#include "mlidar/calib/planes_types.hpp"

namespace mlidar::calib {

/// Closed form from matched, oriented, ordered planes: R by Kabsch on the
/// normals, n_ref = R n_target (eq 2.6); t = o_ref - R o_target (eq 2.7 with
/// R, which the thesis's printed t = o' - o drops).
SE3 closed_form_T_ref_target(const std::array<Plane, 3>& ref_planes, const std::array<Plane, 3>& target_planes);

/// Reorders the target's planes by the cyclic shift (which keeps eq 2.5) that
/// best agrees with a rough rotation R_ref_target: used when an initial guess
/// is given, so the floor heuristic is not needed.
void align_order_to_guess(Corner& target, const Corner& ref, const Quat& R_ref_target);

class PlanesCalibrator {
 public:
  /// Throws UsageError naming the key when the config is out of range.
  explicit PlanesCalibrator(PlanesConfig config);
  const PlanesConfig& config() const { return config_; }

  /// Throws InputError(source, field, ...) when a cloud is empty or holds no
  /// corner (fewer than three planes, or near parallel ones). Warnings for a
  /// weak but usable corner are in the result.
  PlanesResult calibrate(std::span<const Eigen::Vector3f> ref_points, std::span<const Eigen::Vector3f> target_points,
                         const std::optional<SE3>& T_ref_target_guess, const std::string& ref_source,
                         const std::string& target_source) const;

 private:
  Corner corner_of(std::span<const Eigen::Vector3f> points, const std::string& source, std::size_t& planes_found) const;

  PlanesConfig config_;
};

}  // namespace mlidar::calib
