// Hand-eye AX = XB (thesis Sec. 3.4.2) against motion pairs built from a known X.
#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/calib/hand_eye.hpp"
#include "mlidar/core/so3.hpp"
#include "pose_error.hpp"

namespace mlidar::calib {
namespace {

using test::rotation_error_rad;
using test::translation_error_m;

const SE3 kTruth(so3_exp(Vec3(0.3, 3.0, 1.57)), Vec3(-2.5, 1.5, 0.4));  // thesis Fig. 3.7-like

Vec3 gaussian3(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}

/// B_k random (rotations up to ~0.6 rad about any axis, ~1 m steps), A_k = X B_k X^-1.
std::vector<MotionPair> general_pairs(int count, std::uint64_t seed, const SE3& X = kTruth) {
  std::mt19937_64 rng(seed);
  std::vector<MotionPair> pairs;
  for (int k = 0; k < count; ++k) {
    const SE3 B(so3_exp(gaussian3(rng, 0.3)), gaussian3(rng, 1.0));
    pairs.push_back({X * B * X.inverse(), B});
  }
  return pairs;
}

/// Base moves in its x-y plane, turning about its z only.
std::vector<MotionPair> planar_pairs(int count, std::uint64_t seed, double yaw_sigma = 0.3) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<MotionPair> pairs;
  for (int k = 0; k < count; ++k) {
    const SE3 A(so3_exp(Vec3(0, 0, yaw_sigma * n(rng))), Vec3(2.0 + n(rng), n(rng), 0.0));
    pairs.push_back({A, kTruth.inverse() * A * kTruth});
  }
  return pairs;
}

/// Table 3.1's noise: zero-mean Gaussian of variance sigma2 on every motion's
/// rotation vector (rad) and translation (m), for both sensors.
std::vector<MotionPair> add_noise(std::vector<MotionPair> pairs, double sigma2, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const double s = std::sqrt(sigma2);
  const auto perturb = [&](const SE3& T) { return SE3(so3_exp(gaussian3(rng, s)) * T.rotation(), T.translation() + gaussian3(rng, s)); };
  for (MotionPair& p : pairs) p = {perturb(p.A), perturb(p.B)};
  return pairs;
}

HandEyeConfig permissive_filter() {
  HandEyeConfig config;
  config.screw_angle_tolerance_rad = 1.0;
  config.screw_pitch_tolerance_m = 10.0;
  return config;
}

TEST(HandEye, RecoversKnownXFromExactGeneralMotion) {
  const auto pairs = general_pairs(20, 1);
  const HandEyeResult r = solve_hand_eye(pairs);
  ASSERT_EQ(r.verdict, HandEyeVerdict::ok) << r.message;
  EXPECT_LE(rotation_error_rad(r.T_a_b, kTruth), 1e-9);
  EXPECT_LE(translation_error_m(r.T_a_b, kTruth), 1e-9);
  EXPECT_EQ(r.pairs_used, 20u);
  EXPECT_LT(r.singular_values[3], 1e-9 * r.singular_values[0]);  // eq 3.7 has an exact null vector
  EXPECT_GT(r.singular_values[2], 0.05 * r.singular_values[0]);
}

TEST(HandEye, NoisyMotionErrorsShrinkWithNoiseAndCovarianceIsConsistent) {
  for (const double sigma2 : {1e-4, 1e-3}) {
    double worst_rot = 0.0, worst_trans = 0.0;
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const auto pairs = add_noise(general_pairs(100, seed), sigma2, 100 + seed);
      const HandEyeResult r = solve_hand_eye(pairs, permissive_filter());
      ASSERT_EQ(r.verdict, HandEyeVerdict::ok) << r.message;
      worst_rot = std::max(worst_rot, rotation_error_rad(r.T_a_b, kTruth));
      worst_trans = std::max(worst_trans, translation_error_m(r.T_a_b, kTruth));
      // Covariance: symmetric, positive, and the rotation error within ~4 sigma.
      EXPECT_TRUE(r.covariance.isApprox(r.covariance.transpose(), 1e-9));
      EXPECT_GT(r.covariance.diagonal().minCoeff(), 0.0);
      const double rot_sigma = std::sqrt(r.covariance.bottomRightCorner<3, 3>().trace());
      EXPECT_LT(rotation_error_rad(r.T_a_b, kTruth), 4.0 * rot_sigma + 1e-6);
    }
    std::printf("sigma2=%g, 100 pairs, 5 seeds: worst rotation error %.4f rad, translation %.4f m\n", sigma2, worst_rot, worst_trans);
    const double sigma = std::sqrt(sigma2);
    EXPECT_LT(worst_rot, sigma);         // thesis Table 3.1: 0.01-0.07 rad
    EXPECT_LT(worst_trans, 10 * sigma);  // thesis Table 3.1: 0.28-1.44 m
  }
}

TEST(HandEye, ScrewFilterRejectsInjectedOutliers) {
  auto pairs = general_pairs(40, 2);
  const auto wrong = general_pairs(8, 3, SE3(so3_exp(Vec3(1, 0, 0)), Vec3(0, 0, 1)));
  std::vector<std::size_t> outlier_index;
  for (std::size_t i = 0; i < wrong.size(); ++i) {
    const std::size_t at = 5 * i + 1;
    // Outlier: B from one motion, A from another (a lost odometry frame).
    pairs[at] = {wrong[i].A, pairs[at].B};
    outlier_index.push_back(at);
  }
  const HandEyeResult r = solve_hand_eye(pairs);
  ASSERT_EQ(r.verdict, HandEyeVerdict::ok) << r.message;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const bool injected = std::find(outlier_index.begin(), outlier_index.end(), i) != outlier_index.end();
    EXPECT_EQ(r.screw[i].inlier, !injected) << "pair " << i;
  }
  EXPECT_EQ(r.pairs_rejected, outlier_index.size());
  EXPECT_LE(rotation_error_rad(r.T_a_b, kTruth), 1e-9);
  EXPECT_LE(translation_error_m(r.T_a_b, kTruth), 1e-9);
  // Without the filter the same outliers ruin the estimate.
  const HandEyeResult unfiltered = solve_hand_eye(pairs, permissive_filter());
  EXPECT_GT(rotation_error_rad(unfiltered.T_a_b, kTruth) + translation_error_m(unfiltered.T_a_b, kTruth), 1e-3);
}

TEST(HandEye, PlanarMotionDetectedAndSolvedUpToHeight) {
  const auto pairs = planar_pairs(30, 4);
  const HandEyeResult r = solve_hand_eye(pairs);
  ASSERT_EQ(r.verdict, HandEyeVerdict::planar_motion) << r.message;
  EXPECT_FALSE(r.t_z_observable);
  EXPECT_LT(r.singular_values[2], 1e-9 * r.singular_values[0]);  // two-dimensional null space
  EXPECT_NEAR(std::abs(r.planar_axis_a.z()), 1.0, 1e-12);
  EXPECT_LE(rotation_error_rad(r.T_a_b, kTruth), 1e-9);
  const Vec3 dt = r.T_a_b.translation() - kTruth.translation();
  EXPECT_LE(dt.head<2>().norm(), 1e-9);  // x, y recovered; z (along the axis) is not
  EXPECT_NEAR(r.T_a_b.translation().z(), 0.0, 1e-9);
  EXPECT_NEAR(r.covariance(2, 2), HandEyeConfig{}.unobservable_variance, 1e-6);
}

TEST(HandEye, PlanarMotionWithNoise) {
  const auto pairs = add_noise(planar_pairs(100, 5), 1e-6, 7);
  const HandEyeResult r = solve_hand_eye(pairs);
  ASSERT_EQ(r.verdict, HandEyeVerdict::planar_motion) << r.message;
  const Vec3 dt = r.T_a_b.translation() - kTruth.translation();
  std::printf("planar, sigma2=1e-6: rotation error %.5f rad, x-y error %.5f m\n", rotation_error_rad(r.T_a_b, kTruth), dt.head<2>().norm());
  EXPECT_LT(rotation_error_rad(r.T_a_b, kTruth), 0.005);
  EXPECT_LT(dt.head<2>().norm(), 0.02);
}

TEST(HandEye, PureTranslationIsReportedDegenerate) {
  std::vector<MotionPair> pairs;
  for (int k = 0; k < 20; ++k) {
    const SE3 A(Quat::Identity(), Vec3(1.0 + 0.1 * k, 0.05 * k, 0.0));
    pairs.push_back({A, kTruth.inverse() * A * kTruth});
  }
  const HandEyeResult r = solve_hand_eye(pairs);
  EXPECT_EQ(r.verdict, HandEyeVerdict::degenerate_motion);
  EXPECT_FALSE(r.message.empty());
}

TEST(HandEye, SpinningInPlaceAboutOneAxisIsReportedDegenerate) {
  std::vector<MotionPair> pairs;
  for (int k = 0; k < 20; ++k) {
    const SE3 A(so3_exp(Vec3(0, 0, 0.1 + 0.05 * k)), Vec3::Zero());
    pairs.push_back({A, kTruth.inverse() * A * kTruth});
  }
  const HandEyeResult r = solve_hand_eye(pairs);
  EXPECT_EQ(r.verdict, HandEyeVerdict::degenerate_motion) << r.message;
}

TEST(HandEye, TooFewPairs) {
  const HandEyeResult r = solve_hand_eye(general_pairs(2, 1));
  EXPECT_EQ(r.verdict, HandEyeVerdict::too_few_pairs);
  EXPECT_EQ(solve_hand_eye({}).verdict, HandEyeVerdict::too_few_pairs);
}

TEST(HandEye, PairOrderDoesNotMatter) {
  auto pairs = add_noise(general_pairs(60, 8), 1e-4, 9);
  const HandEyeResult forward = solve_hand_eye(pairs, permissive_filter());
  std::shuffle(pairs.begin(), pairs.end(), std::mt19937_64(10));
  const HandEyeResult shuffled = solve_hand_eye(pairs, permissive_filter());
  EXPECT_LE(rotation_error_rad(forward.T_a_b, shuffled.T_a_b), 1e-9);
  EXPECT_LE(translation_error_m(forward.T_a_b, shuffled.T_a_b), 1e-9);
}

TEST(HandEye, RejectsBadConfig) {
  HandEyeConfig config;
  config.planar_singular_ratio = 2.0;
  EXPECT_THROW(solve_hand_eye(general_pairs(5, 1), config), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::calib
