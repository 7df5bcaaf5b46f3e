#pragma once
// Motion compensation (thesis eq 4.11-4.12) under constant velocity.
// The base moves with a constant body velocity: over tau seconds after the
// frame stamp its pose relative to the stamp is (Exp(tau w), tau v) (rotation
// interpolated on SO(3), translation linearly, as eq 4.11). A point p captured
// by a LiDAR at time t (seconds from the frame stamp, any sign, so LiDARs with
// different sweep starts all come to the same stamp) is brought to the base
// frame at the stamp:
//   p_base = Exp(t w) (T_base_lidar p) + t v.
#include <span>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"

namespace mlidar::slam {

/// Body velocity of the base: v (m/s) and w (rad/s), both in the base frame.
struct BodyVelocity {
  Vec3 linear = Vec3::Zero();
  Vec3 angular = Vec3::Zero();

  /// From the relative pose T_prev_curr = T_world_prev^-1 T_world_curr over dt seconds:
  /// the constant velocity that reproduces it under the decoupled model.
  static BodyVelocity from_relative_pose(const SE3& T_prev_curr, double dt);
  /// Pose of the base tau seconds after the stamp relative to the stamp.
  SE3 pose_at(double tau) const;
};

/// out[i] = Exp(times[i] w) (T_base_lidar points[i]) + times[i] v for the
/// chosen `indices` (all points when indices is empty, in order). out.size()
/// must equal indices.size() (or points.size()); times has one entry per
/// point or is empty (no motion: out = T_base_lidar p). Throws
/// std::invalid_argument when sizes disagree or an index is out of range.
void deskew_to_base(std::span<const Eigen::Vector3f> points, std::span<const float> times, std::span<const std::uint32_t> indices,
                    const SE3& T_base_lidar, const BodyVelocity& velocity, std::span<Eigen::Vector3f> out);

/// Points deskewed with `used` (by deskew_to_base) deskewed again with `refined`:
/// p = Exp(t w_r) Exp(-t w_u) (p_u - t v_u) + t v_r (the base-frame capture point
/// recovered, then moved with the refined velocity). times has one entry per point
/// or is empty (nothing changes); throws std::invalid_argument when sizes disagree.
void redeskew(std::span<const float> times, const BodyVelocity& used, const BodyVelocity& refined, std::span<Eigen::Vector3f> points);

}  // namespace mlidar::slam
