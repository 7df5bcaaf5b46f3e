// Chordal and robust (geodesic L1, Weiszfeld) rotation means.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "lie_test_util.hpp"
#include "mlidar/core/rotation_average.hpp"

namespace mlidar {
namespace {

using test::random_rotation_vector;
using test::rotation_error_rad;

Quat random_rotation(std::mt19937& rng) { return so3_exp(random_rotation_vector(rng, 0.0, std::numbers::pi)); }

TEST(ChordalMean, NoiseFreeCopiesGiveTheRotation) {
  std::mt19937 rng(41);
  for (int i = 0; i < 50; ++i) {
    const Quat truth = random_rotation(rng);
    std::vector<Quat> copies(7, truth);
    copies[3].coeffs() *= -1.0;  // same rotation, other sign
    EXPECT_LT(rotation_error_rad(chordal_mean(copies), truth), 1e-14);
    EXPECT_LT(rotation_error_rad(robust_rotation_mean(copies).mean, truth), 1e-14);
  }
}

// Rotations about one axis: sum w_i Rz(a_i) projects to Rz(atan2(sum w sin a, sum w cos a)).
TEST(ChordalMean, WeightedMeanAboutOneAxis) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  std::uniform_real_distribution<double> weight(0.1, 5.0);
  for (int i = 0; i < 50; ++i) {
    const Quat frame = random_rotation(rng);
    const Vec3 axis = frame * Vec3::UnitZ();
    std::vector<Quat> rotations;
    std::vector<double> weights;
    double sum_sin = 0.0;
    double sum_cos = 0.0;
    for (int k = 0; k < 5; ++k) {
      const double a = angle(rng);
      weights.push_back(weight(rng));
      rotations.push_back(so3_exp(a * axis));
      sum_sin += weights.back() * std::sin(a);
      sum_cos += weights.back() * std::cos(a);
    }
    const Quat expected = so3_exp(std::atan2(sum_sin, sum_cos) * axis);
    EXPECT_LT(rotation_error_rad(chordal_mean(rotations, weights), expected), 1e-12);
  }
}

TEST(ChordalMean, ZeroWeightIgnoresARotation) {
  const std::vector<Quat> rotations = {so3_exp(Vec3(0.1, 0.2, 0.3)), so3_exp(Vec3(-1.0, 2.0, 0.5))};
  const std::vector<double> weights = {2.0, 0.0};
  EXPECT_LT(rotation_error_rad(chordal_mean(rotations, weights), rotations[0]), 1e-14);
}

TEST(ChordalMean, RejectsBadInput) {
  const std::vector<Quat> two(2, Quat::Identity());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(chordal_mean({}), std::invalid_argument);
  EXPECT_THROW(robust_rotation_mean({}), std::invalid_argument);
  EXPECT_THROW(chordal_mean(two, std::vector<double>{1.0}), std::invalid_argument);
  EXPECT_THROW(chordal_mean(two, std::vector<double>{1.0, -1.0}), std::invalid_argument);
  EXPECT_THROW(chordal_mean(two, std::vector<double>{1.0, nan}), std::invalid_argument);
  EXPECT_THROW(chordal_mean(two, std::vector<double>{0.0, 0.0}), std::invalid_argument);
}

struct OutlierCase {
  Quat truth;
  std::vector<Quat> rotations;
};

// 70 inliers with 1e-4 rad noise, 30 gross outliers: either uniformly random
// or clustered around one wrong rotation (a systematic failure mode).
OutlierCase make_outlier_case(std::mt19937& rng, bool clustered) {
  std::normal_distribution<double> inlier_noise(0.0, 1e-4);
  OutlierCase c;
  c.truth = random_rotation(rng);
  for (int i = 0; i < 70; ++i) {
    const Vec3 noise(inlier_noise(rng), inlier_noise(rng), inlier_noise(rng));
    c.rotations.push_back(c.truth * so3_exp(noise));
  }
  const Quat wrong = c.truth * so3_exp(random_rotation_vector(rng, 0.8, 1.5));
  for (int i = 0; i < 30; ++i) {
    c.rotations.push_back(clustered ? wrong * so3_exp(random_rotation_vector(rng, 0.0, 0.3)) : random_rotation(rng));
  }
  std::shuffle(c.rotations.begin(), c.rotations.end(), rng);
  return c;
}

TEST(RobustMean, IgnoresThirtyPercentClusteredOutliers) {
  std::mt19937 rng(43);
  for (int trial = 0; trial < 10; ++trial) {
    const OutlierCase c = make_outlier_case(rng, /*clustered=*/true);
    const RobustMeanResult robust = robust_rotation_mean(c.rotations);
    const double robust_error = rotation_error_rad(robust.mean, c.truth);
    const double chordal_error = rotation_error_rad(chordal_mean(c.rotations), c.truth);
    EXPECT_TRUE(robust.converged);
    EXPECT_LT(robust_error, 1e-3);
    EXPECT_GT(chordal_error, 0.1) << "the chordal mean should be dragged by the outlier cluster";
  }
}

TEST(RobustMean, IgnoresThirtyPercentUniformOutliers) {
  std::mt19937 rng(44);
  for (int trial = 0; trial < 10; ++trial) {
    const OutlierCase c = make_outlier_case(rng, /*clustered=*/false);
    const RobustMeanResult robust = robust_rotation_mean(c.rotations);
    const double robust_error = rotation_error_rad(robust.mean, c.truth);
    const double chordal_error = rotation_error_rad(chordal_mean(c.rotations), c.truth);
    EXPECT_TRUE(robust.converged);
    EXPECT_LT(robust_error, 1e-3);
    EXPECT_LT(robust_error, chordal_error);
  }
}

// The result minimises the L1 cost: no small perturbation lowers it.
TEST(RobustMean, IsALocalMinimumOfTheL1Cost) {
  std::mt19937 rng(45);
  const OutlierCase c = make_outlier_case(rng, /*clustered=*/true);
  const RobustMeanResult robust = robust_rotation_mean(c.rotations);
  auto cost = [&](const Quat& mean) {
    double sum = 0.0;
    for (const Quat& r : c.rotations) sum += rotation_error_rad(mean, r);
    return sum;
  };
  EXPECT_NEAR(robust.cost, cost(robust.mean), 1e-9);
  for (int i = 0; i < 50; ++i) {
    const Quat moved = robust.mean * so3_exp(random_rotation_vector(rng, 1e-5, 1e-3));
    EXPECT_GE(cost(moved), robust.cost - 1e-9);
  }
}

}  // namespace
}  // namespace mlidar
