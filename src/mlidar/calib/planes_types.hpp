#pragma once
// Configuration and result of PS-Calib, the one-shot calibration of two
// LiDARs from a wall corner (thesis Chap. 2).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"
#include "mlidar/geometry/plane_fit.hpp"

namespace mlidar::calib {

/// Defaults: the thesis's where it gives one (pairwise plane angles 60-120 deg,
/// widened by 5 deg so a 60 deg corner seen with noise still qualifies; at
/// most 1000 LM iterations); the rest chosen for its synthetic protocol
/// (sigma = 0.1 m) and indoor 16-beam scans.
/// A PlanesConfig value out of range: its key and the range expected.
struct PlanesConfigProblem {
  const char* key;
  const char* expected;
};

struct PlanesConfig {
  double inlier_distance = 0.2;             ///< m, RANSAC and final inlier band
  int ransac_iterations = 1000;             ///< hypotheses per plane at most
  int max_planes = 6;                       ///< planes extracted per cloud (a room scan has more than three)
  std::size_t min_plane_points = 100;       ///< smaller planes are not extracted
  double min_corner_angle_deg = 55.0;       ///< pairwise angles in [this, 180 - this]: the thesis's 60-120 less 5 deg for noise
  double min_any_angle_deg = 15.0;          ///< below this two planes count as parallel: no corner
  double corner_max_gap = 2.0;              ///< m, corner farther than this from a plane's inliers warns
  std::size_t warn_min_inliers = 300;       ///< fewer inliers on a plane warns
  std::size_t max_points_per_plane = 4000;  ///< refinement subsample per plane and cloud
  double huber_delta = 0.1;                 ///< m, robust loss of the refinement (eq 2.8)
  int max_iterations = 1000;                ///< LM iterations at most (thesis)
  double max_rotation_sigma_deg = 0.5;      ///< largest rotation std. dev. before "poorly conditioned"
  Vec3 up = Vec3::UnitZ();                  ///< rough up axis in both LiDAR frames (picks the floor, eq 2.5)
  std::uint64_t seed = 1;                   ///< RANSAC seed

  /// The first value out of range, or nullopt.
  std::optional<PlanesConfigProblem> problem() const;
  /// Throws UsageError naming the key of the first value out of range.
  void validate() const;
};

enum class PlanesWarning : std::uint8_t {
  kPlanesNearlyParallel,       ///< a pairwise angle outside [min_corner_angle, 180 - min_corner_angle]
  kFewInliers,                 ///< a plane with fewer than warn_min_inliers points
  kCornerOutsideClouds,        ///< the corner lies farther than corner_max_gap from a plane's points
  kRotationPoorlyConditioned,  ///< smallest eigenvalue of the rotation information below 1/max_rotation_sigma^2
  kNotConverged,               ///< LM stopped at max_iterations
};

/// "planes_nearly_parallel", "few_inliers", "corner_outside_clouds",
/// "rotation_poorly_conditioned", "not_converged".
const char* warning_name(PlanesWarning warning);

/// One plane of the corner in its own LiDAR's frame, oriented by eq 2.4.
struct CornerPlaneReport {
  Plane plane;
  std::size_t inliers = 0;
  double residual_rms = 0.0;  ///< m, after refinement
};

struct CloudCornerReport {
  std::size_t planes_found = 0;             ///< by RANSAC, before the triple is chosen
  std::array<CornerPlaneReport, 3> planes;  ///< left, right, bottom (eq 2.5)
  std::array<double, 3> angles_deg{};       ///< between planes (1,2), (1,3), (2,3)
  Vec3 corner = Vec3::Zero();               ///< eq 2.3
};

struct PlanesResult {
  SE3 T_ref_target;                     ///< p_ref = R p_target + t
  SE3 T_ref_target_closed_form;         ///< eq 2.6-2.7, before refinement
  Mat6 covariance = Mat6::Zero();       ///< [t, r]: t_true = t + e_t, R_true = R Exp(e_r)
  double residual_sigma = 0.0;          ///< m, scale of the covariance
  double rotation_sigma_max_deg = 0.0;  ///< sqrt of the largest eigenvalue of the rotation block
  CloudCornerReport ref;
  CloudCornerReport target;
  int iterations = 0;
  bool converged = false;
  std::vector<PlanesWarning> warnings;
  bool ok() const { return warnings.empty(); }
};

}  // namespace mlidar::calib
