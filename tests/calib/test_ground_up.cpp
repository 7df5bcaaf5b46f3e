// calib::ground_up on synthetic scans: a tilted LiDAR over flat ground with
// a larger wall beside it; the ground's normal is found from a prior 17 deg
// off, the wall never wins, and nothing qualifies without ground below.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/calib/ground_up.hpp"

namespace mlidar::calib {
namespace {

/// Ground z = -1.3 (3000 points) and a wall x = 4 (5000 points) in the world, seen from a LiDAR rotated by R_world_lidar at the origin.
std::vector<Eigen::Vector3f> scene(const Quat& R_world_lidar, bool with_ground, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-8.0, 8.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<Eigen::Vector3f> points;
  const Quat R_lidar_world = R_world_lidar.conjugate();
  if (with_ground)
    for (int i = 0; i < 3000; ++i) points.push_back((R_lidar_world * Vec3(u(rng), u(rng), -1.3 + noise(rng))).cast<float>());
  for (int i = 0; i < 5000; ++i) points.push_back((R_lidar_world * Vec3(4.0 + noise(rng), u(rng), 0.25 * u(rng))).cast<float>());
  return points;
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

TEST(GroundUp, FindsTheGroundNormalFromAPriorSeventeenDegreesOff) {
  const Quat R_world_lidar = so3_exp(Vec3(0.7, 0.0, 0.3));  // rolled 40 deg, yawed
  const Vec3 true_up = R_world_lidar.conjugate() * Vec3::UnitZ();
  const Quat shock = so3_exp(true_up.cross(Vec3(1, 1, 1)).normalized() * 0.3);  // a 17 deg tilt
  const Vec3 prior_up = shock * true_up;
  ASSERT_GT(angle_deg(prior_up, true_up), 15.0);
  const std::optional<Vec3> up = ground_up(scene(R_world_lidar, true, 1), prior_up);
  ASSERT_TRUE(up.has_value());
  EXPECT_LT(angle_deg(*up, true_up), 0.5);
  EXPECT_NEAR(up->norm(), 1.0, 1e-12);
  // No ground: the wall (more points, horizontal normal) does not qualify.
  EXPECT_FALSE(ground_up(scene(R_world_lidar, false, 2), prior_up).has_value());
  // Ground above the sensor (prior pointing down) does not qualify either.
  EXPECT_FALSE(ground_up(scene(R_world_lidar, true, 3), -true_up).has_value());
}

TEST(GroundUp, AlignUpMapsUpOntoZWithTheSmallestCorrection) {
  const Quat R_g_lidar = so3_exp(Vec3(0.2, -0.1, 1.0));
  const Vec3 up_lidar = (R_g_lidar.conjugate() * so3_exp(Vec3(0.1, 0.2, 0.0)) * Vec3::UnitZ()).normalized();
  const Quat aligned = align_up(R_g_lidar, up_lidar);
  EXPECT_LT((aligned * up_lidar - Vec3::UnitZ()).norm(), 1e-12);
  // The correction is the angle between the old up and z, nothing more.
  const double correction = so3_log(aligned * R_g_lidar.conjugate()).norm();
  EXPECT_NEAR(correction, std::acos((R_g_lidar * up_lidar).dot(Vec3::UnitZ())), 1e-12);
}

}  // namespace
}  // namespace mlidar::calib
