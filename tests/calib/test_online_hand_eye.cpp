// Online hand-eye (thesis eq 4.15-4.18) against motion pairs built from a known X.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/calib/online_hand_eye.hpp"
#include "mlidar/core/so3.hpp"
#include "pose_error.hpp"

namespace mlidar::calib {
namespace {

using test::rotation_error_rad;

const SE3 kTruth(so3_exp(Vec3(0.3, -0.4, 1.2)), Vec3(-0.5, 0.3, 0.4));  // T_base_lidar

constexpr double kDeg = std::numbers::pi / 180.0;

Vec3 gaussian3(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}

/// Base motion A (rotation vector `phi_a`, translation `t_a`), LiDAR motion B = X^-1 A X.
MotionPair exact_pair(const Vec3& phi_a, const Vec3& t_a, const SE3& X = kTruth) {
  const SE3 A(so3_exp(phi_a), t_a);
  return {A, X.inverse() * A * X};
}

std::vector<MotionPair> general_pairs(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<MotionPair> pairs;
  for (int k = 0; k < count; ++k) pairs.push_back(exact_pair(gaussian3(rng, 0.2), gaussian3(rng, 0.5)));
  return pairs;
}

/// Noise on each motion's rotation vector (rad) and translation (m), both sensors.
MotionPair perturb(const MotionPair& p, std::mt19937_64& rng, double sigma_r, double sigma_t) {
  const auto noisy = [&](const SE3& T) {
    return SE3(so3_exp(gaussian3(rng, sigma_r)) * T.rotation(), T.translation() + gaussian3(rng, sigma_t));
  };
  return {noisy(p.A), noisy(p.B)};
}

OnlineHandEye fed(std::span<const MotionPair> pairs, OnlineHandEyeConfig config = {}) {
  OnlineHandEye online(config);
  for (const MotionPair& p : pairs) online.add(p);
  return online;
}

TEST(OnlineHandEye, RecoversXFromExactPairs) {
  const auto pairs = general_pairs(40, 1);
  OnlineHandEye online;
  EXPECT_EQ(online.status().state, OnlineHandEyeState::collecting);
  online.add(pairs[0]);
  EXPECT_EQ(online.status().state, OnlineHandEyeState::collecting);  // one pair leaves a 2-D null space
  for (std::size_t k = 1; k < pairs.size(); ++k) online.add(pairs[k]);
  const OnlineHandEyeStatus& s = online.status();
  ASSERT_EQ(s.state, OnlineHandEyeState::ready);
  EXPECT_GT(s.singular_values[2], 0.25);
  EXPECT_LT(s.singular_values[3], 1e-9 * s.singular_values[0]);  // an exact null vector
  EXPECT_FALSE(s.planar_motion);
  EXPECT_LE(rotation_error_rad(s.T_base_lidar, kTruth), 1e-9);
  EXPECT_LE((s.T_base_lidar.translation() - kTruth.translation()).norm(), 1e-9);
  EXPECT_EQ(s.pairs_stored, 40u);
  EXPECT_EQ(s.pairs_seen, 40u);
  EXPECT_LE(s.rotation_rms_rad, 1e-9);
}

TEST(OnlineHandEye, ReadyExactlyWhenSecondSmallestSingularValuePassesSigmaR) {
  const auto pairs = general_pairs(60, 2);
  OnlineHandEye online;
  bool was_ready = false;
  for (const MotionPair& p : pairs) {
    online.add(p);
    const OnlineHandEyeStatus& s = online.status();
    EXPECT_EQ(s.state != OnlineHandEyeState::collecting, s.singular_values[2] > 0.25) << s.pairs_stored;
    was_ready = was_ready || s.state == OnlineHandEyeState::ready;
  }
  EXPECT_TRUE(was_ready);
}

TEST(OnlineHandEye, SeededNoisyPairsGiveAnAccurateEstimate) {
  std::mt19937_64 rng(3);
  const auto pairs = general_pairs(300, 4);
  OnlineHandEye online;
  for (const MotionPair& p : pairs) online.add(perturb(p, rng, 0.002, 0.005));
  const OnlineHandEyeStatus& s = online.status();
  ASSERT_EQ(s.state, OnlineHandEyeState::ready);
  EXPECT_LT(rotation_error_rad(s.T_base_lidar, kTruth), 0.5 * kDeg);
  EXPECT_LT((s.T_base_lidar.translation() - kTruth.translation()).norm(), 0.02);
  EXPECT_GT(s.rotation_rms_rad, 0.0);
}

TEST(OnlineHandEye, HuberWeightsReduceTheEffectOfGrossOutliers) {
  std::mt19937_64 rng(5);
  std::vector<MotionPair> pairs;
  for (const MotionPair& p : general_pairs(200, 6)) {
    pairs.push_back(perturb(p, rng, 0.002, 0.005));
    if (pairs.size() % 10 == 0) pairs.back().B = SE3(so3_exp(gaussian3(rng, 0.3)), gaussian3(rng, 0.5));  // a lost frame
  }
  OnlineHandEyeConfig unweighted;
  unweighted.huber_delta_rad = 10.0;  // every residual inside delta: weight 1
  const double robust = rotation_error_rad(fed(pairs).status().T_base_lidar, kTruth);
  const double plain = rotation_error_rad(fed(pairs, unweighted).status().T_base_lidar, kTruth);
  EXPECT_LT(robust, 0.5 * plain);
  EXPECT_LT(robust, 1.0 * kDeg);
}

TEST(OnlineHandEye, PureTranslationStaysCollecting) {
  std::mt19937_64 rng(7);
  OnlineHandEye online;
  for (int k = 0; k < 300; ++k) online.add(exact_pair(Vec3::Zero(), gaussian3(rng, 1.0)));
  EXPECT_EQ(online.status().state, OnlineHandEyeState::collecting);
  EXPECT_LT(online.status().singular_values[0], 1e-9);
}

TEST(OnlineHandEye, SingleAxisRotationStaysCollecting) {
  std::mt19937_64 rng(8);
  std::normal_distribution<double> n(0.0, 0.3);
  const Vec3 axis = Vec3(0.2, -0.5, 1.0).normalized();
  OnlineHandEye online;
  for (int k = 0; k < 300; ++k) online.add(exact_pair(n(rng) * axis, gaussian3(rng, 1.0)));
  const OnlineHandEyeStatus& s = online.status();
  EXPECT_EQ(s.state, OnlineHandEyeState::collecting);
  EXPECT_GT(s.singular_values[1], 1.0);   // the rotation itself is well excited...
  EXPECT_LT(s.singular_values[2], 1e-9);  // ...but the rotation about the axis is not
}

TEST(OnlineHandEye, PlanarMotionFlagsTheAxisAndFixesItsTranslationToZero) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  OnlineHandEye online;
  for (int k = 0; k < 300; ++k) {  // a ground robot: yaw turns, a little roll/pitch from bumps, x-y travel
    online.add(exact_pair(Vec3(0.03 * n(rng), 0.03 * n(rng), 0.3 * n(rng)), Vec3(1.0 + n(rng), n(rng), 0.0)));
  }
  const OnlineHandEyeStatus& s = online.status();
  ASSERT_EQ(s.state, OnlineHandEyeState::ready);
  EXPECT_TRUE(s.planar_motion);
  EXPECT_GT(s.unobservable_axis_base.z(), 0.99);
  EXPECT_LE(rotation_error_rad(s.T_base_lidar, kTruth), 1e-9);
  const Vec3& axis = s.unobservable_axis_base;
  EXPECT_NEAR(s.T_base_lidar.translation().dot(axis), 0.0, 1e-12);
  const Vec3 observable_truth = kTruth.translation() - axis * axis.dot(kTruth.translation());
  EXPECT_LE((s.T_base_lidar.translation() - observable_truth).norm(), 1e-9);
  EXPECT_LT(s.translation_eigenvalues[0], 0.05 * s.translation_eigenvalues[2]);
}

TEST(OnlineHandEye, BoundedStoreKeepsTheLargestRotations) {
  OnlineHandEyeConfig config;
  config.max_constraints = 10;
  OnlineHandEye online(config);
  std::mt19937_64 rng(10);
  std::vector<double> angles;
  std::vector<MotionPair> pairs;
  for (int k = 0; k < 30; ++k) {
    const double angle = 0.01 * ((k * 7) % 30 + 1);  // a permutation of 0.01 .. 0.30
    const Vec3 axis = gaussian3(rng, 1.0).normalized();
    pairs.push_back(exact_pair(angle * axis, gaussian3(rng, 1.0)));
    const double smallest_stored = angles.size() < 10 ? 0.0 : *std::min_element(angles.begin(), angles.end());
    const PairOutcome outcome = online.add(pairs.back());
    if (angles.size() < 10) {
      EXPECT_EQ(outcome, PairOutcome::stored);
      angles.push_back(angle);
    } else if (angle <= smallest_stored) {
      EXPECT_EQ(outcome, PairOutcome::dropped_small);
    } else {
      EXPECT_EQ(outcome, PairOutcome::replaced_smallest);
      *std::min_element(angles.begin(), angles.end()) = angle;
    }
    EXPECT_EQ(online.status().pairs_stored, std::min<std::size_t>(k + 1, 10));
  }
  std::vector<double> stored;
  for (const MotionPair& p : online.pairs()) stored.push_back(so3_log(p.A.rotation()).norm());
  std::sort(stored.begin(), stored.end());
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(stored[i], 0.01 * (21 + i), 1e-12);  // the ten largest of 30
  EXPECT_EQ(online.status().pairs_seen, 30u);
}

TEST(OnlineHandEye, RejectsNonFinitePairsAndResets) {
  OnlineHandEye online;
  MotionPair bad = exact_pair(Vec3(0.1, 0, 0), Vec3(1, 0, 0));
  bad.B = SE3(bad.B.rotation(), Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0));
  EXPECT_EQ(online.add(bad), PairOutcome::rejected_invalid);
  EXPECT_EQ(online.status().pairs_stored, 0u);
  for (const MotionPair& p : general_pairs(40, 11)) online.add(p);
  EXPECT_EQ(online.status().state, OnlineHandEyeState::ready);
  online.reset();
  EXPECT_EQ(online.status().state, OnlineHandEyeState::collecting);
  EXPECT_EQ(online.status().pairs_stored, 0u);
  OnlineHandEyeConfig tiny;
  tiny.max_constraints = 1;
  EXPECT_THROW(OnlineHandEye{tiny}, std::invalid_argument);
}

TEST(OnlineHandEye, ResidualAngleIsZeroForExactPairsAndTheMisalignmentOtherwise) {
  const MotionPair p = exact_pair(Vec3(0.2, 0.1, -0.3), Vec3(1, 2, 3));
  EXPECT_NEAR(hand_eye_residual_angle(p, kTruth.rotation()), 0.0, 1e-12);
  EXPECT_GT(hand_eye_residual_angle(p, so3_exp(Vec3(0.1, 0, 0)) * kTruth.rotation()), 1e-3);
}

}  // namespace
TEST(OnlineHandEye, PairsWithInvalidTranslationGiveRotationOnly) {
  // Every pair's rotations are exact; most translations of B are wrong by
  // decimetres (a LiDAR's odometry sliding in a degenerate scene). Flagged as
  // translation-invalid, they still fix the rotation, and t comes from the rest.
  std::mt19937_64 rng(21);
  OnlineHandEye flagged;
  OnlineHandEye unflagged;
  int k = 0;
  for (MotionPair p : general_pairs(60, 22)) {
    const bool valid = k++ % 4 == 0;
    if (!valid) p.B = SE3(p.B.rotation(), p.B.translation() + gaussian3(rng, 0.3));
    flagged.add(p, valid);
    unflagged.add(p);
  }
  ASSERT_EQ(flagged.status().state, OnlineHandEyeState::ready);
  EXPECT_EQ(flagged.status().pairs_translation, 15u);
  EXPECT_LE(rotation_error_rad(flagged.status().T_base_lidar, kTruth), 1e-9);
  EXPECT_LE((flagged.status().T_base_lidar.translation() - kTruth.translation()).norm(), 1e-9);
  EXPECT_LT(flagged.status().translation_std_m, 1e-6);
  // The same pairs all used: the translation is off and its predicted std says so.
  EXPECT_GT((unflagged.status().T_base_lidar.translation() - kTruth.translation()).norm(), 0.01);
  EXPECT_GT(unflagged.status().translation_std_m, 0.01);
}

TEST(OnlineHandEye, TranslationStdGateHoldsBackAPoorTranslation) {
  std::mt19937_64 rng(23);
  std::vector<MotionPair> noisy;
  for (const MotionPair& p : general_pairs(30, 24)) noisy.push_back(perturb(p, rng, 1e-4, 0.1));
  OnlineHandEyeConfig strict;
  strict.translation_max_std_m = 0.01;
  const OnlineHandEye gated = fed(noisy, strict);
  EXPECT_EQ(gated.status().state, OnlineHandEyeState::rotation_ready);
  EXPECT_GT(gated.status().translation_std_m, 0.01);
  OnlineHandEyeConfig loose;
  loose.translation_max_std_m = 10.0;
  EXPECT_EQ(fed(noisy, loose).status().state, OnlineHandEyeState::ready);
}

TEST(OnlineHandEye, PlanarRotationStartsFromTranslationsWithTheAxisFlagged) {
  // A ground robot turning about the base's z only (eq 4.17's test cannot
  // pass): with planar_rotation the start is eq 3.8-3.12, exact on exact pairs
  // except t along z, which is 0 and flagged.
  std::mt19937_64 rng(25);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<MotionPair> pairs;
  for (int k = 0; k < 60; ++k) pairs.push_back(exact_pair(Vec3(0.0, 0.0, 0.3 * n(rng)), Vec3(1.0 + n(rng), n(rng), 0.0)));
  EXPECT_EQ(fed(pairs).status().state, OnlineHandEyeState::collecting);  // off by default
  OnlineHandEyeConfig planar;
  planar.planar_rotation = true;
  const OnlineHandEyeStatus s = fed(pairs, planar).status();
  ASSERT_EQ(s.state, OnlineHandEyeState::ready);
  EXPECT_TRUE(s.planar_motion);
  EXPECT_TRUE(s.planar_rotation);
  EXPECT_GT(s.unobservable_axis_base.z(), 0.999);
  EXPECT_LE(rotation_error_rad(s.T_base_lidar, kTruth), 1e-6);
  EXPECT_NEAR(s.T_base_lidar.translation().z(), 0.0, 1e-9);
  EXPECT_LE((s.T_base_lidar.translation().head<2>() - kTruth.translation().head<2>()).norm(), 1e-6);
  // Pure yaw without translation leaves the rotation about z unobservable: no start.
  std::vector<MotionPair> spinning;
  for (int k = 0; k < 60; ++k) spinning.push_back(exact_pair(Vec3(0.0, 0.0, 0.3 * n(rng)), Vec3::Zero()));
  EXPECT_NE(fed(spinning, planar).status().state, OnlineHandEyeState::ready);
}

}  // namespace mlidar::calib
