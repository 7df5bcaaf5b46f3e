// SO(3) slerp, SE(3) geodesic interpolation and pose lookup in a Trajectory.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lie_test_util.hpp"
#include "mlidar/core/trajectory_interpolation.hpp"

namespace mlidar {
namespace {

using test::pose_distance;
using test::random_pose;
using test::random_twist;
using test::rotation_error_rad;

TEST(Slerp, MatchesEigenSlerpAndEndpoints) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const Quat a = so3_exp(test::random_rotation_vector(rng, 0.0, 3.1));
    const Quat b = so3_exp(test::random_rotation_vector(rng, 0.0, 3.1));
    const double s = fraction(rng);
    EXPECT_LT(rotation_error_rad(so3_slerp(a, b, s), a.slerp(s, b)), 1e-12);
    EXPECT_LT(rotation_error_rad(so3_slerp(a, b, 0.0), a), 1e-14);
    EXPECT_LT(rotation_error_rad(so3_slerp(a, b, 1.0), b), 1e-14);
  }
}

TEST(Slerp, ConstantAngularVelocity) {
  std::mt19937 rng(32);
  for (int i = 0; i < 100; ++i) {
    const Quat a = so3_exp(test::random_rotation_vector(rng, 0.0, 3.1));
    const Vec3 omega = test::random_rotation_vector(rng, 0.0, 3.0);
    const Quat b = a * so3_exp(omega);
    for (const double s : {0.25, 0.5, 0.75}) {
      EXPECT_LT(rotation_error_rad(so3_slerp(a, b, s), a * so3_exp(s * omega)), 1e-12);
    }
  }
}

TEST(SE3Interpolate, Endpoints) {
  std::mt19937 rng(33);
  for (int i = 0; i < 100; ++i) {
    const SE3 a = random_pose(rng);
    const SE3 b = random_pose(rng);
    EXPECT_LT(pose_distance(interpolate(a, b, 0.0), a), 1e-12);
    EXPECT_LT(pose_distance(interpolate(a, b, 1.0), b), 1e-12);
  }
}

// b = a exp(xi): the geodesic is the constant body-twist motion a exp(s xi),
// so the midpoint is a exp(xi / 2) and it splits the motion into two equal halves.
TEST(SE3Interpolate, ConstantVelocityMidpoint) {
  std::mt19937 rng(34);
  for (int i = 0; i < 200; ++i) {
    const SE3 a = random_pose(rng);
    const Vec6 xi = random_twist(rng, 0.0, 3.0);
    const SE3 b = a * SE3::exp(xi);
    const SE3 mid = interpolate(a, b, 0.5);
    EXPECT_LT(pose_distance(mid, a * SE3::exp(0.5 * xi)), 1e-10);
    EXPECT_LT(pose_distance(a.inverse() * mid, mid.inverse() * b), 1e-10);
    for (const double s : {0.1, 0.3, 0.9}) {
      EXPECT_LT(pose_distance(interpolate(a, b, s), a * SE3::exp(s * xi)), 1e-10);
      EXPECT_LT(pose_distance(interpolate(a, b, s), interpolate(b, a, 1.0 - s)), 1e-10);
    }
  }
}

// Poses along T0 exp(t xi) at uneven stamps: lookup at any t inside must give
// T0 exp(t xi) exactly (the motion has constant twist in every segment).
Trajectory constant_twist_trajectory(const SE3& start, const Vec6& xi, const std::vector<double>& stamps) {
  Trajectory trajectory;
  for (const double t : stamps) trajectory.poses.push_back({t, start * SE3::exp(t * xi)});
  return trajectory;
}

TEST(TrajectoryInterpolation, ReproducesConstantTwistMotion) {
  std::mt19937 rng(35);
  const std::vector<double> stamps = {10.0, 10.1, 10.25, 10.7, 10.71, 11.0};
  std::uniform_real_distribution<double> time(stamps.front(), stamps.back());
  for (int i = 0; i < 50; ++i) {
    const SE3 start = random_pose(rng);
    const Vec6 xi = random_twist(rng, 0.0, 2.0);  // per second: under pi per segment
    const Trajectory trajectory = constant_twist_trajectory(start, xi, stamps);
    for (int k = 0; k < 20; ++k) {
      const double t = time(rng);
      const std::optional<SE3> pose = interpolate_pose(trajectory, t);
      ASSERT_TRUE(pose.has_value()) << t;
      EXPECT_LT(pose_distance(*pose, start * SE3::exp(t * xi)), 1e-8) << t;
    }
    for (const StampedPose& stamped : trajectory.poses) {
      const std::optional<SE3> pose = interpolate_pose(trajectory, stamped.stamp);
      ASSERT_TRUE(pose.has_value());
      EXPECT_EQ(pose->matrix(), stamped.T_world_base.matrix());
    }
  }
}

TEST(TrajectoryInterpolation, OutOfRangeGivesNullopt) {
  std::mt19937 rng(36);
  const Trajectory trajectory = constant_twist_trajectory(random_pose(rng), random_twist(rng, 0.0, 1.0), {1.0, 2.0, 3.0});
  EXPECT_FALSE(interpolate_pose(trajectory, 0.999999).has_value());
  EXPECT_FALSE(interpolate_pose(trajectory, 3.000001).has_value());
  EXPECT_FALSE(interpolate_pose(trajectory, std::numeric_limits<double>::quiet_NaN()).has_value());
  EXPECT_FALSE(interpolate_pose(trajectory, std::numeric_limits<double>::infinity()).has_value());
  EXPECT_FALSE(interpolate_pose(Trajectory{}, 1.0).has_value());
  EXPECT_TRUE(interpolate_pose(trajectory, 1.0).has_value());
  EXPECT_TRUE(interpolate_pose(trajectory, 3.0).has_value());
}

TEST(TrajectoryInterpolation, SinglePoseAndDuplicatedStamps) {
  std::mt19937 rng(37);
  const SE3 a = random_pose(rng);
  const SE3 b = random_pose(rng);
  Trajectory single;
  single.poses.push_back({5.0, a});
  ASSERT_TRUE(interpolate_pose(single, 5.0).has_value());
  EXPECT_EQ(interpolate_pose(single, 5.0)->matrix(), a.matrix());
  EXPECT_FALSE(interpolate_pose(single, 5.1).has_value());

  Trajectory duplicated;
  duplicated.poses = {{1.0, a}, {1.0, b}, {2.0, b}};
  const std::optional<SE3> at_duplicate = interpolate_pose(duplicated, 1.0);
  ASSERT_TRUE(at_duplicate.has_value());
  EXPECT_TRUE(pose_distance(*at_duplicate, a) == 0.0 || pose_distance(*at_duplicate, b) == 0.0);
  ASSERT_TRUE(interpolate_pose(duplicated, 1.5).has_value());
  EXPECT_LT(pose_distance(*interpolate_pose(duplicated, 1.5), b), 1e-12);
}

// Violated precondition (unordered stamps): a finite pose, never a crash.
TEST(TrajectoryInterpolation, UnorderedStampsStayInBounds) {
  std::mt19937 rng(38);
  Trajectory unordered;
  for (const double t : {0.0, 5.0, 1.0, 3.0, 2.0, 10.0}) unordered.poses.push_back({t, random_pose(rng)});
  for (double t = 0.0; t <= 10.0; t += 0.25) {
    const std::optional<SE3> pose = interpolate_pose(unordered, t);
    ASSERT_TRUE(pose.has_value());
    EXPECT_TRUE(pose->matrix().allFinite());
  }
}

}  // namespace
}  // namespace mlidar
