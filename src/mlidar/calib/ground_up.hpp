#pragma once
// The up direction of a LiDAR from one scan: the normal of its ground plane.
// After an extrinsic shock the LiDAR's rotation is unknown by up to the
// shock (thesis Table 4.6: 10 deg about each axis, ~14 deg of tilt), more
// than the ground segmentation's slope tolerance (10 deg), so the own
// odometry that re-initializes it must not take "up" from the old
// extrinsic. Ground: among the planes of a sequential RANSAC
// (geometry/plane_ransac.hpp), those whose normal lies within
// `max_angle_rad` of `prior_up` and that pass at least `min_below_m` below
// the sensor; the one with most inliers wins.
#include <optional>
#include <span>

#include <Eigen/Core>

#include "mlidar/core/so3.hpp"

namespace mlidar::calib {

struct GroundUpConfig {
  double max_angle_rad = 0.6;  ///< ~34 deg: twice the thesis's shock tilt
  double min_below_m = 0.3;    ///< the sensor is at least this high above the ground
  double inlier_distance_m = 0.1;
  std::size_t min_inliers = 200;
};

/// Unit up (pointing from the ground to the sensor) in the points' frame, or
/// nullopt when no plane qualifies. Deterministic (seeded RANSAC).
std::optional<Vec3> ground_up(std::span<const Eigen::Vector3f> points, const Vec3& prior_up, const GroundUpConfig& config = {});

/// The rotation closest to `R_g_lidar` that maps `up_lidar` onto +z of g:
/// R_g_lidar corrected by the smallest rotation taking R_g_lidar up_lidar to z.
Quat align_up(const Quat& R_g_lidar, const Vec3& up_lidar);

}  // namespace mlidar::calib
