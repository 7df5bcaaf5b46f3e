// Uncertain-pose compounding (Barfoot & Furgale's fourth-order covariance) and
// LiDAR point covariances against seeded Monte Carlo runs of 10^5 samples.
#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "mlidar/core/pose_uncertainty.hpp"

namespace mlidar {
namespace {

constexpr int kMonteCarloSamples = 100000;

/// ||estimate - reference||_F / ||reference||_F.
template <typename Matrix>
double relative_frobenius_error(const Matrix& estimate, const Matrix& reference) {
  return (estimate - reference).norm() / reference.norm();
}

/// A covariance with the given 1-sigmas and seeded, non-zero correlations between all entries.
Mat6 correlated_covariance(const Vec6& sigmas, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Mat6 factor;
  for (int i = 0; i < factor.size(); ++i) {
    factor(i) = normal(rng);
  }
  const Mat6 spread = factor * factor.transpose() + 3.0 * Mat6::Identity();
  const Vec6 spread_sd = spread.diagonal().cwiseSqrt();
  const Mat6 correlation = spread.cwiseQuotient(spread_sd * spread_sd.transpose());
  return sigmas.asDiagonal() * correlation * sigmas.asDiagonal();
}

/// Draws x ~ N(0, L L^T) from a lower Cholesky factor.
template <int N>
Eigen::Matrix<double, N, 1> draw(const Eigen::Matrix<double, N, N>& lower_factor, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Matrix<double, N, 1> standard;
  for (int i = 0; i < N; ++i) {
    standard(i) = normal(rng);
  }
  return lower_factor * standard;
}

/// E[xi xi^T] of xi = Log(Exp(xi_a) Ta Exp(xi_b) Tb (Ta Tb)^-1), by sampling.
Mat6 monte_carlo_compound_covariance(const UncertainPose& a, const UncertainPose& b, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Mat6 factor_a = a.covariance.llt().matrixL();
  const Mat6 factor_b = b.covariance.llt().matrixL();
  const SE3 mean_inverse = (a.T * b.T).inverse();
  Mat6 second_moment = Mat6::Zero();
  for (int i = 0; i < kMonteCarloSamples; ++i) {
    const SE3 sample = SE3::exp(draw<6>(factor_a, rng)) * a.T * SE3::exp(draw<6>(factor_b, rng)) * b.T;
    const Vec6 xi = (sample * mean_inverse).log();
    second_moment += xi * xi.transpose();
  }
  return second_moment / kMonteCarloSamples;
}

/// Sample covariance of y = Exp(xi) T (p + zeta).
Mat3 monte_carlo_point_covariance(const UncertainPose& pose, const Vec3& p, const Mat3& Z, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Mat6 factor_pose = pose.covariance.llt().matrixL();
  const Mat3 factor_point = Z.llt().matrixL();
  Vec3 sum = Vec3::Zero();
  Mat3 sum_outer = Mat3::Zero();
  for (int i = 0; i < kMonteCarloSamples; ++i) {
    const Vec3 noisy_p = p + draw<3>(factor_point, rng);
    const Vec3 y = SE3::exp(draw<6>(factor_pose, rng)) * (pose.T * noisy_p);
    sum += y;
    sum_outer += y * y.transpose();
  }
  const Vec3 mean = sum / kMonteCarloSamples;
  return (sum_outer - kMonteCarloSamples * mean * mean.transpose()) / (kMonteCarloSamples - 1);
}

SE3 pose_from(double tx, double ty, double tz, double rx, double ry, double rz) {
  Vec6 xi;
  xi << tx, ty, tz, rx, ry, rz;
  return SE3::exp(xi);
}

Vec6 sigmas_of(double t0, double t1, double t2, double r0, double r1, double r2) {
  Vec6 sigmas;
  sigmas << t0, t1, t2, r0, r1, r2;
  return sigmas;
}

// Ta rotates by ~1 rad and moves a few metres.
UncertainPose first_pose(const Vec6& sigmas) { return {pose_from(2.0, -1.5, 3.0, 0.6, -0.5, 0.6), correlated_covariance(sigmas, 11)}; }
UncertainPose second_pose(const Vec6& sigmas) { return {pose_from(1.0, 0.5, -0.8, -0.2, 0.4, 0.3), correlated_covariance(sigmas, 23)}; }

TEST(PoseUncertainty, CompoundMatchesMonteCarloForRealisticNoise) {
  const UncertainPose a = first_pose(sigmas_of(0.1, 0.2, 0.15, 0.05, 0.08, 0.06));
  const UncertainPose b = second_pose(sigmas_of(0.3, 0.1, 0.2, 0.1, 0.07, 0.05));
  const Mat6 sampled = monte_carlo_compound_covariance(a, b, 1);

  // Measured: 0.7 % (the second-order one 0.75 %); at these sigmas both sit at the
  // Monte Carlo noise floor (~sqrt(2 / N)).
  EXPECT_LT(relative_frobenius_error(compound(a, b).covariance, sampled), 0.05);
}

TEST(PoseUncertainty, CompoundFourthOrderBeatsSecondOrderForLargeRotationNoise) {
  const UncertainPose a = first_pose(sigmas_of(0.2, 0.3, 0.25, 0.25, 0.3, 0.2));
  const UncertainPose b = second_pose(sigmas_of(0.3, 0.2, 0.2, 0.3, 0.2, 0.25));
  const Mat6 sampled = monte_carlo_compound_covariance(a, b, 2);

  const double fourth_order_error = relative_frobenius_error(compound(a, b).covariance, sampled);
  const double second_order_error = relative_frobenius_error(compound_covariance_second_order(a, b), sampled);
  // Measured: fourth order 0.5 %, second order 2.7 % (with 2e6 samples: 0.17 % and 2.6 %,
  // so the second-order error is the missing terms, not sampling noise).
  EXPECT_LT(fourth_order_error, 0.5 * second_order_error);
}

TEST(PoseUncertainty, CompoundOfCertainPosesIsCertain) {
  const UncertainPose a{pose_from(2.0, -1.5, 3.0, 0.6, -0.5, 0.6), Mat6::Zero()};
  const UncertainPose b{pose_from(1.0, 0.5, -0.8, -0.2, 0.4, 0.3), Mat6::Zero()};
  const UncertainPose ab = compound(a, b);
  EXPECT_EQ(ab.covariance, Mat6::Zero());
  EXPECT_LT((ab.T.matrix() - (a.T * b.T).matrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(PoseUncertainty, CompoundWithCertainSecondPoseKeepsFirstCovariance) {
  const UncertainPose a = first_pose(sigmas_of(0.2, 0.3, 0.25, 0.25, 0.3, 0.2));
  const UncertainPose b{pose_from(1.0, 0.5, -0.8, -0.2, 0.4, 0.3), Mat6::Zero()};
  const UncertainPose ab = compound(a, b);
  EXPECT_LT((ab.covariance - a.covariance).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((ab.T.matrix() - (a.T * b.T).matrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(PoseUncertainty, CompoundWithCertainFirstPoseMovesSecondCovarianceByAdjoint) {
  const UncertainPose a{pose_from(2.0, -1.5, 3.0, 0.6, -0.5, 0.6), Mat6::Zero()};
  const UncertainPose b = second_pose(sigmas_of(0.3, 0.2, 0.2, 0.3, 0.2, 0.25));
  const Mat6 adjoint = a.T.adjoint();
  const Mat6 expected = adjoint * b.covariance * adjoint.transpose();
  EXPECT_LT((compound(a, b).covariance - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((compound_covariance_second_order(a, b) - expected).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(PointCovariance, MatchesMonteCarloForModeratePoseNoise) {
  const UncertainPose T_world_lidar{pose_from(5.0, -2.0, 1.5, 0.3, -0.8, 0.5),
                                    correlated_covariance(sigmas_of(0.05, 0.08, 0.04, 0.01, 0.02, 0.015), 5)};
  const Vec3 p_lidar(12.0, -6.0, 2.0);
  const Mat3 Z = lidar_point_noise(p_lidar, 0.03, 0.003);
  const Mat3 sampled = monte_carlo_point_covariance(T_world_lidar, p_lidar, Z, 3);

  // Measured: 0.74 %.
  EXPECT_LT(relative_frobenius_error(point_covariance(T_world_lidar, p_lidar, Z), sampled), 0.05);
}

TEST(PointCovariance, WithCertainPoseIsRotatedSensorNoise) {
  const UncertainPose T_world_lidar{pose_from(5.0, -2.0, 1.5, 0.3, -0.8, 0.5), Mat6::Zero()};
  const Vec3 p_lidar(12.0, -6.0, 2.0);
  const Mat3 Z = lidar_point_noise(p_lidar, 0.03, 0.003);
  const Mat3 R = T_world_lidar.T.rotation_matrix();
  EXPECT_LT((point_covariance(T_world_lidar, p_lidar, Z) - R * Z * R.transpose()).cwiseAbs().maxCoeff(), 1e-12);
}

// The closed form for many points of one pose is the general H Theta H^T with Z = lidar_point_noise.
TEST(PointCovariance, TheClosedFormForOnePoseIsTheGeneralOne) {
  const UncertainPose T_world_lidar{pose_from(5.0, -2.0, 1.5, 0.3, -0.8, 0.5),
                                    correlated_covariance(sigmas_of(0.05, 0.08, 0.04, 0.01, 0.02, 0.015), 5)};
  const BeamPointCovariance beam(T_world_lidar, 0.03, 0.003);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> coordinate(-60.0, 60.0);
  for (int i = 0; i < 200; ++i) {
    const Vec3 p_lidar(coordinate(rng), coordinate(rng), coordinate(rng));
    const Mat3 general = point_covariance(T_world_lidar, p_lidar, lidar_point_noise(p_lidar, 0.03, 0.003));
    EXPECT_LT((beam(p_lidar) - general).cwiseAbs().maxCoeff(), 1e-12 * general.cwiseAbs().maxCoeff()) << p_lidar.transpose();
  }
  const Mat3 at_origin = point_covariance(T_world_lidar, Vec3::Zero(), lidar_point_noise(Vec3::Zero(), 0.03, 0.003));
  EXPECT_LT((beam(Vec3::Zero()) - at_origin).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LidarPointNoise, EigenvaluesAreRangeAlongBeamAndLateralAcross) {
  const Vec3 p_lidar(30.0, -40.0, 0.0);  // r = 50 m
  const double range_sigma = 0.02;
  const double angular_sigma = 0.001;
  const Mat3 Z = lidar_point_noise(p_lidar, range_sigma, angular_sigma);
  const double range_variance = range_sigma * range_sigma;
  const double lateral_variance = std::pow(50.0 * angular_sigma, 2);

  const Vec3 u = p_lidar.normalized();
  EXPECT_NEAR(u.dot(Z * u), range_variance, 1e-15);
  EXPECT_LT((Z * u - range_variance * u).norm(), 1e-15);
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(Z);
  const Vec3 expected(range_variance, lateral_variance, lateral_variance);  // ascending: 4e-4 < 2.5e-3
  EXPECT_LT((solver.eigenvalues() - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LidarPointNoise, FarPointIsMoreUncertainThanNearPoint) {
  const Vec3 direction = Vec3(1.0, 2.0, -0.5).normalized();
  const Mat3 near = lidar_point_noise(5.0 * direction, 0.02, 0.002);
  const Mat3 far = lidar_point_noise(80.0 * direction, 0.02, 0.002);
  EXPECT_GT(far.trace(), near.trace());
  EXPECT_NEAR(far.trace() - near.trace(), 2.0 * (80.0 * 80.0 - 5.0 * 5.0) * 0.002 * 0.002, 1e-12);
}

TEST(LidarPointNoise, OriginGetsIsotropicRangeNoise) {
  const Mat3 Z = lidar_point_noise(Vec3::Zero(), 0.02, 0.002);
  EXPECT_TRUE(Z.allFinite());
  EXPECT_EQ(Z, 0.02 * 0.02 * Mat3::Identity());
}

}  // namespace
}  // namespace mlidar
