#pragma once
// Start poses for registering a target LiDAR to a reference one from a bad
// guess. The ground fixes three of the six degrees of freedom: the target's
// ground plane (one of its largest planes, normal towards the sensor) is
// rotated onto the reference's (its largest near-horizontal plane), which
// sets roll, pitch and the height along the normal; the yaw about the ground
// normal is then swept over a full turn, and the in-plane translation is the
// guess's, or a grid about it when xy_radius_m > 0 (a guess metres off).
// Without a reference ground the starts are the guess rotated about each of
// its axes.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"
#include "mlidar/geometry/plane_fit.hpp"
#include "mlidar/geometry/plane_ransac.hpp"

namespace mlidar::calib {

struct CoarseSearchConfig {
  PlaneRansacConfig ransac{
      .inlier_distance = 0.08, .max_iterations = 300, .min_inliers = 100, .max_planes = 3, .refine_passes = 2, .seed = 1};
  double voxel_size = 0.3;           ///< m, clouds are thinned before RANSAC
  double ref_ground_tilt_deg = 45;   ///< the reference ground's normal lies within this of the reference z
  int target_ground_candidates = 3;  ///< largest target planes tried as its ground
  double yaw_step_deg = 15.0;        ///< yaw sweep step about the ground normal
  double fallback_step_deg = 45.0;   ///< without a ground: offsets about each axis of the guess
  double xy_radius_m = 0.0;          ///< in-plane translations within this of the guess's (0: the guess's only)
  double xy_step_m = 1.0;            ///< spacing of that grid
};

struct StartPose {
  SE3 T_ref_target;
  std::string label;  ///< how it was made, e.g. "ground plane 1, yaw 120 deg"
};

/// The reference's ground: its largest plane whose normal lies within ref_ground_tilt_deg of its z,
/// the normal towards the sensor; nullopt without one.
std::optional<Plane> reference_ground(std::span<const Eigen::Vector3f> ref, const CoarseSearchConfig& config);

/// Starts in a deterministic order; the guess itself is not among them.
std::vector<StartPose> coarse_starts(std::span<const Eigen::Vector3f> ref, std::span<const Eigen::Vector3f> target, const SE3& T_guess,
                                     const CoarseSearchConfig& config = {});

}  // namespace mlidar::calib
