// calib::calibration_covariance on sequences whose variance of the mean is
// known in closed form: AR(1) (the accepted windows' slowly varying error) and
// a moving average over 5 frames (windows of N + 1 = 5 frames sharing 4);
// the window-covariance change of tangent against exact perturbations.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/calib/extrinsic_covariance.hpp"

namespace mlidar::calib {
namespace {

/// Var of the mean of n samples of a stationary sequence with unit variance and autocorrelation rho(k).
template <typename Rho>
double variance_of_mean(int n, Rho rho) {
  double sum = n;
  for (int k = 1; k < n; ++k) sum += 2.0 * (n - k) * rho(k);
  return sum / (static_cast<double>(n) * n);
}

/// Six independent AR(1) components x_i = phi x_{i-1} + sqrt(1 - phi^2) e_i, unit variance, stationary start.
std::vector<Vec6> ar1(int n, double phi, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  std::vector<Vec6> x(n);
  for (int c = 0; c < 6; ++c) x[0](c) = normal(rng);
  for (int i = 1; i < n; ++i)
    for (int c = 0; c < 6; ++c) x[i](c) = phi * x[i - 1](c) + std::sqrt(1.0 - phi * phi) * normal(rng);
  return x;
}

std::vector<Vec6> centred(std::vector<Vec6> x) {
  Vec6 mean = Vec6::Zero();
  for (const Vec6& v : x) mean += v;
  mean /= static_cast<double>(x.size());
  for (Vec6& v : x) v -= mean;
  return x;
}

TEST(CalibrationCovariance, Ar1VarianceOfTheMeanIsRecovered) {
  constexpr int kLength = 400;
  constexpr int kReplicates = 200;
  constexpr double kPhi = 0.8;  // tau = (1 + phi) / (1 - phi) = 9
  std::mt19937_64 rng(7);
  double tau_sum = 0.0;
  Vec6 spread_sum = Vec6::Zero();
  for (int r = 0; r < kReplicates; ++r) {
    const std::vector<Vec6> x = centred(ar1(kLength, kPhi, rng));
    const CalibrationCovariance c = calibration_covariance(x, {}, 1.0);
    tau_sum += c.autocorrelation_time;
    spread_sum += c.spread.diagonal();
  }
  const double truth = variance_of_mean(kLength, [&](int k) { return std::pow(kPhi, k); });
  EXPECT_NEAR(tau_sum / kReplicates, 9.0, 0.9);
  for (int c = 0; c < 6; ++c) EXPECT_NEAR(spread_sum(c) / kReplicates / truth, 1.0, 0.12) << c;
  // The plain sample covariance / n (the old Xi_calib) is 9x too small.
  EXPECT_LT(1.0 / kLength / truth, 0.15);
}

TEST(CalibrationCovariance, OverlappingWindowsOfFiveFramesWithTheOverlapFloor) {
  // x_i = mean of frames i..i+4 (i.i.d. unit frames): rho_k = (5 - k) / 5, tau = 5; L_calib = 25 estimates.
  constexpr int kAccepted = 25;
  constexpr int kWindow = 5;
  constexpr int kReplicates = 2000;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  double spread_sum = 0.0;
  double plain_sum = 0.0;
  for (int r = 0; r < kReplicates; ++r) {
    std::vector<Vec6> frames(kAccepted + kWindow - 1);
    for (Vec6& f : frames)
      for (int c = 0; c < 6; ++c) f(c) = normal(rng);
    std::vector<Vec6> x(kAccepted, Vec6::Zero());
    for (int i = 0; i < kAccepted; ++i)
      for (int k = 0; k < kWindow; ++k) x[i] += frames[i + k] / kWindow;
    const CalibrationCovariance c = calibration_covariance(centred(x), {}, kWindow);
    EXPECT_GE(c.autocorrelation_time, kWindow);
    spread_sum += c.spread.trace() / 6.0;
    plain_sum += c.spread.trace() / 6.0 / c.autocorrelation_time;
  }
  // Unit frames: Var(x_i) = 1 / 5.
  const double truth = variance_of_mean(kAccepted, [&](int k) { return k < kWindow ? (kWindow - k) / double(kWindow) : 0.0; }) / kWindow;
  // Within 25 %: S itself is biased low by the correlation (E S = 0.85 Var x_i here), tau is floored at 5.
  EXPECT_NEAR(spread_sum / kReplicates / truth, 1.0, 0.25);
  EXPECT_LT(plain_sum / kReplicates / truth, 0.3);  // S / n: 4-5x too small
}

TEST(CalibrationCovariance, WindowsTermIsTheMeanOfTheWindowCovariancesAndAddsToTheSpread) {
  const std::vector<Vec6> same(3, Vec6::Zero());
  const std::vector<Mat6> windows = {Mat6::Identity(), 3.0 * Mat6::Identity(), 2.0 * Mat6::Identity()};
  const CalibrationCovariance c = calibration_covariance(same, windows, 5.0);
  EXPECT_TRUE(c.spread.isZero());
  EXPECT_TRUE(c.total.isApprox(2.0 * Mat6::Identity()));
  EXPECT_DOUBLE_EQ(c.autocorrelation_time, 3.0);  // the floor 5 clamped to n
  EXPECT_THROW(calibration_covariance(same, std::vector<Mat6>(2, Mat6::Identity()), 1.0), std::invalid_argument);
  EXPECT_THROW(calibration_covariance(std::vector<Vec6>(1, Vec6::Zero()), {}, 1.0), std::invalid_argument);
}

TEST(CalibrationCovariance, LocalCovarianceKeepsTheMahalanobisDistanceOfLeftPerturbations) {
  // For d ~ small, e = [t' - t, Log(R^T R')] of T' = Exp(d) T satisfies e^T C^-1 e = d^T (Lambda / sigma^2) d.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  const SE3 T(so3_exp(Vec3(0.7, -0.2, 0.4)), Vec3(0.3, -0.477, -0.22));
  Mat6 A;
  for (int i = 0; i < 36; ++i) A(i / 6, i % 6) = normal(rng);
  const Mat6 information = A * A.transpose() + Mat6::Identity();
  constexpr double kVariance = 4e-4;
  const Mat6 C = local_covariance_from_left_information(T, information, kVariance);
  for (int trial = 0; trial < 5; ++trial) {
    Vec6 d;
    for (int c = 0; c < 6; ++c) d(c) = 1e-4 * normal(rng);
    const SE3 moved = SE3::exp(d) * T;
    Vec6 e;
    e << moved.translation() - T.translation(), so3_log(T.rotation().conjugate() * moved.rotation());
    const double expected = d.dot(information * d) / kVariance;
    EXPECT_NEAR(e.dot(C.ldlt().solve(e)) / expected, 1.0, 1e-3) << trial;
  }
}

}  // namespace
}  // namespace mlidar::calib
