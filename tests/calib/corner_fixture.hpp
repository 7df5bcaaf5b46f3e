#pragma once
// In-memory wall corner for the calib tests (the same geometry as
// `mlidar simulate corner`, thesis Sec. 2.4.2): walls through the z axis at
// angle alpha, floor z = 0, each 10 m across; l1 4 m from the corner on the
// bisector, 1.5 m up, facing it; l2 = l1 * T_l1_l2.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/se3.hpp"

namespace mlidar::test {

struct CornerClouds {
  std::vector<Eigen::Vector3f> ref;
  std::vector<Eigen::Vector3f> target;
  SE3 T_ref_target;
};

/// R = Rz(yaw) Ry(pitch) Rx(roll) (rad), the library's roll-pitch-yaw convention, and t.
inline SE3 zyx_pose(double yaw, double pitch, double roll, const Vec3& t) { return SE3(quat_from_rpy(Vec3(roll, pitch, yaw)), t); }

/// Table 2.2 configuration 1 or 2 (read as ZYX Euler angles, as the simulator does).
inline SE3 thesis_configuration(int which) {
  return which == 1 ? zyx_pose(2.7337, -0.3946, -0.1809, Vec3(0.8766, 0.4672, 1.0474))
                    : zyx_pose(-0.5174, 0.1277, 0.1222, Vec3(1.3785, -1.3929, 1.3020));
}

/// `planar` points over the `planes` first planes of the corner (floor last), `outliers` N(0, 5^2) points.
inline std::vector<Vec3> corner_world_points(double alpha, int planar, int outliers, double noise, int planes, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Vec3 wall2(std::cos(alpha), std::sin(alpha), 0.0);
  std::vector<Vec3> points;
  for (int i = 0; i < planar; ++i) {
    const int which = planes == 3 ? i % 3 : (planes == 2 ? i % 2 : 0);
    Vec3 p;
    if (which == 0) p = Vec3(10 * u(rng), 0, 10 * u(rng));
    if (which == 1) p = 10 * u(rng) * wall2 + Vec3(0, 0, 10 * u(rng));
    if (which == 2) {
      const double r = 10 * std::sqrt(u(rng));
      const double theta = alpha * u(rng);
      p = Vec3(r * std::cos(theta), r * std::sin(theta), 0.0);
    }
    points.push_back(p + noise * Vec3(gauss(rng), gauss(rng), gauss(rng)));
  }
  const Vec3 middle(5 * std::cos(alpha / 2), 5 * std::sin(alpha / 2), 5);
  while (static_cast<int>(points.size()) < planar + outliers) {
    const Vec3 offset = 5.0 * Vec3(gauss(rng), gauss(rng), gauss(rng));
    if ((offset.array().abs() <= 5.0).all()) points.push_back(middle + offset);
  }
  return points;
}

inline std::vector<Eigen::Vector3f> to_lidar(const std::vector<Vec3>& world, const SE3& T_world_lidar) {
  const SE3 T_lidar_world = T_world_lidar.inverse();
  std::vector<Eigen::Vector3f> out;
  for (const Vec3& p : world) out.push_back((T_lidar_world * p).cast<float>());
  return out;
}

inline CornerClouds make_corner(double alpha_deg, const SE3& T_ref_target, int planar, int outliers, double noise, std::uint64_t seed,
                                int planes = 3) {
  const double alpha = alpha_deg * std::numbers::pi / 180.0;
  const SE3 T_world_ref = zyx_pose(alpha / 2 + std::numbers::pi, 0.0, 0.0, Vec3(4 * std::cos(alpha / 2), 4 * std::sin(alpha / 2), 1.5));
  std::mt19937_64 rng(seed);
  CornerClouds clouds;
  clouds.T_ref_target = T_ref_target;
  clouds.ref = to_lidar(corner_world_points(alpha, planar, outliers, noise, planes, rng), T_world_ref);
  clouds.target = to_lidar(corner_world_points(alpha, planar, outliers, noise, planes, rng), T_world_ref * T_ref_target);
  return clouds;
}

}  // namespace mlidar::test
