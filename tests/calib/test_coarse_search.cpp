// calib::coarse_starts: the ground fixes roll, pitch and height; the yaw sweep
// and (with xy_radius_m) the in-plane grid then contain a start near the truth
// even when the guess's translation is metres off (a bumper LiDAR after a weak
// hand-eye), and the grid adds nothing when it is off.
#include <random>

#include <gtest/gtest.h>

#include "mlidar/calib/coarse_search.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

// Target 2.3 m ahead, 0.95 m left, 1.3 m below the reference, yawed 45 deg, tilted 1 deg.
const SE3 kT_ref_target(so3_exp(Vec3(0.0, 0.0, deg_to_rad(45.0))) * so3_exp(Vec3(deg_to_rad(1.0), 0.0, 0.0)), Vec3(2.3, 0.95, -1.3));

/// Ground z = -1.8 in the reference frame and two walls, seen by the reference and by the target at kT_ref_target.
std::pair<std::vector<Eigen::Vector3f>, std::vector<Eigen::Vector3f>> scene() {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-15.0, 15.0);
  std::vector<Eigen::Vector3f> ref, target;
  for (int i = 0; i < 6000; ++i) {
    for (const Vec3& p :
         {Vec3(u(rng), u(rng), -1.8), Vec3(9.0, u(rng), -1.8 + 0.1 * (u(rng) + 15.0)), Vec3(u(rng), -7.0, -1.8 + 0.1 * (u(rng) + 15.0))}) {
      ref.push_back(p.cast<float>());
      target.push_back((kT_ref_target.inverse() * p).cast<float>());
    }
  }
  return {ref, target};
}

double nearest_translation_m(const std::vector<StartPose>& starts, double max_rotation_deg) {
  double best = 1e9;
  for (const StartPose& s : starts)
    if (rad_to_deg(s.T_ref_target.rotation().angularDistance(kT_ref_target.rotation())) <= max_rotation_deg)
      best = std::min(best, (s.T_ref_target.translation() - kT_ref_target.translation()).norm());
  return best;
}

TEST(CoarseSearch, GridAboutAFarGuessHoldsAStartNearTheTruth) {
  const auto [ref, target] = scene();
  const SE3 far_guess(SE3::identity().rotation(), Vec3(0.0, 0.0, 0.0));  // 2.8 m and 45 deg off
  CoarseSearchConfig config;
  config.yaw_step_deg = 15.0;
  const std::vector<StartPose> without = coarse_starts(ref, target, far_guess, config);
  ASSERT_FALSE(without.empty());
  // Without the grid the in-plane translation stays the guess's: 2.5 m off in x-y at best.
  EXPECT_GT(nearest_translation_m(without, 8.0), 2.4);
  config.xy_radius_m = 3.0;
  config.xy_step_m = 1.0;
  const std::vector<StartPose> with = coarse_starts(ref, target, far_guess, config);
  // 29 grid points (|offset| <= 3 m at 1 m spacing) for every yaw and ground candidate.
  EXPECT_EQ(with.size(), without.size() * 29);
  // Some start within half a grid diagonal (0.71 m) and half a yaw step (+ the 1 deg tilt) of the truth.
  EXPECT_LT(nearest_translation_m(with, 8.6), 0.71);
  // Its height is the truth's: the ground sets it.
  for (const StartPose& s : with)
    if (rad_to_deg(s.T_ref_target.rotation().angularDistance(kT_ref_target.rotation())) <= 8.6) {
      EXPECT_NEAR(s.T_ref_target.translation().z(), kT_ref_target.translation().z(), 0.1) << s.label;
    }
}

TEST(CoarseSearch, ReferenceGroundIsTheLargestLevelPlane) {
  const auto [ref, target] = scene();
  const std::optional<Plane> ground = reference_ground(ref, {});
  ASSERT_TRUE(ground.has_value());
  EXPECT_GT(ground->normal.z(), 0.999);
  EXPECT_NEAR(ground->offset, 1.8, 0.02);  // n.p + d = 0 at z = -1.8 with n towards the sensor (+z)
}

}  // namespace
}  // namespace mlidar::calib
