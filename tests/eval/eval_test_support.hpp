#pragma once
// Trajectories with known shapes for the eval tests.
#include <cmath>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::eval::test {

/// A 3D curve with varying heading, pitch and roll; stamps 0.1 s apart from `t0`.
inline Trajectory wavy_trajectory(std::size_t count, double t0 = 100.0) {
  Trajectory trajectory;
  for (std::size_t i = 0; i < count; ++i) {
    const double s = 0.05 * static_cast<double>(i);
    const Vec3 position(10.0 * std::cos(s) + s, 6.0 * std::sin(1.3 * s), 0.5 * std::sin(3.0 * s));
    const Quat rotation = so3_exp(Vec3(0.1 * std::sin(2.0 * s), 0.05 * std::cos(s), s));
    trajectory.poses.push_back({t0 + 0.1 * static_cast<double>(i), SE3(rotation, position)});
  }
  return trajectory;
}

inline std::vector<SE3> poses_of(const Trajectory& trajectory) {
  std::vector<SE3> poses;
  for (const StampedPose& pose : trajectory.poses) poses.push_back(pose.T_world_base);
  return poses;
}

}  // namespace mlidar::eval::test
