// Extrinsic perturbation on points (thesis 6.4): eq 6.9's printed matrix, eq
// 6.6's Jacobian written out by hand, Monte Carlo of eq 6.1-6.3, the bounded
// sampling of 6.6.1.3 and the two routes to the file's tangent.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/covariance.hpp"
#include "mlidar/core/extrinsic_perturbation.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar {
namespace {

/// 6.4.2's ground truth: roll, pitch, yaw 10 deg, t = (1, 1, 1) m; p = (10, 10, 10) m.
SE3 toy_extrinsic() { return SE3(quat_from_rpy_deg(Vec3(10.0, 10.0, 10.0)), Vec3(1.0, 1.0, 1.0)); }
const Vec3 kToyPoint(10.0, 10.0, 10.0);

TEST(ExtrinsicPerturbation, ReproducesTheMatrixOfEq69) {
  // The thesis prints Xi ~ alpha [2.36 -1.24 -1.20; -1.24 2.41 -1.18; -1.20 -1.18 2.49] for eq 6.8's prior.
  // Those numbers come from H = [I, -(R p + t)^, R], i.e. (rho, phi) as a left perturbation of the whole
  // transform (core's UncertainPose), without the alpha-free Z.
  Mat3 printed;
  printed << 2.36, -1.24, -1.20, -1.24, 2.41, -1.18, -1.20, -1.18, 2.49;
  for (const double alpha : {0.02, 0.1, 1.0}) {
    PerturbationPrior prior;
    prior.alpha = alpha;
    const Mat3 xi = point_covariance({toy_extrinsic(), perturbation_covariance(prior)}, kToyPoint, Mat3::Zero());
    EXPECT_LT((xi / alpha - printed).cwiseAbs().maxCoeff(), 0.006) << "alpha " << alpha << "\n" << xi / alpha;
  }
}

TEST(ExtrinsicPerturbation, PointCovarianceIsEq66WrittenOut) {
  PerturbationPrior prior;
  prior.alpha = 0.04;
  const SE3 T = toy_extrinsic();
  const Mat3 R = T.rotation_matrix();
  const Vec3 Rp = R * kToyPoint;
  // H = [I, -(R p)^, R] (eq 6.6), Theta = diag(alpha P, alpha Phi, Z) (eq 6.8).
  Eigen::Matrix<double, 3, 9> H;
  H << Mat3::Identity(), -hat(Rp), R;
  Eigen::Matrix<double, 9, 1> theta;
  theta << Vec3::Constant(0.04 / 400.0), Vec3::Constant(0.04 / 100.0), Vec3::Constant(1.0 / 2500.0);
  const Mat3 expected = H * theta.asDiagonal() * H.transpose();
  const Mat3 xi = perturbed_point_covariance(T, prior, kToyPoint);
  EXPECT_LT((xi - expected).cwiseAbs().maxCoeff(), 1e-12) << xi << "\n" << expected;
  // A LiDAR away from the base origin: eq 6.6 (rotation about the LiDAR) is smaller than eq 6.9's reading.
  const Mat3 left_reading = point_covariance({T, perturbation_covariance(prior)}, kToyPoint, prior_point_noise(prior));
  EXPECT_LT(xi.trace(), left_reading.trace());
}

TEST(ExtrinsicPerturbation, MatchesMonteCarloOfEq61To63) {
  PerturbationPrior prior;
  prior.alpha = 0.02;
  const SE3 T = toy_extrinsic();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int draws = 200000;
  Vec3 mean = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (int i = 0; i < draws; ++i) {
    Vec3 rho, phi, zeta;
    for (int k = 0; k < 3; ++k) rho(k) = prior.scaled_translation_sigma() * normal(rng);
    for (int k = 0; k < 3; ++k) phi(k) = prior.scaled_rotation_sigma() * normal(rng);
    for (int k = 0; k < 3; ++k) zeta(k) = prior.point_sigma_m * normal(rng);
    const Vec3 y = so3_exp(phi) * T.rotation() * (kToyPoint + zeta) + T.translation() + rho;  // eq 6.4
    mean += y;
    second += y * y.transpose();
  }
  mean /= draws;
  const Mat3 sampled = second / draws - mean * mean.transpose();
  const Mat3 xi = perturbed_point_covariance(T, prior, kToyPoint);
  EXPECT_LT((sampled - xi).norm() / xi.norm(), 0.02) << sampled << "\n" << xi;
}

TEST(ExtrinsicPerturbation, SamplesAreBoundedAtSigmaWithTheTruncatedVariance) {
  PerturbationPrior prior;
  prior.alpha = 0.1;
  const SE3 T = toy_extrinsic();
  std::mt19937_64 rng(3);
  const int draws = 40000;
  Vec6 second = Vec6::Zero();
  for (int i = 0; i < draws; ++i) {
    const SE3 perturbed = sample_perturbed_extrinsic(T, prior, rng);
    const Vec3 rho = perturbed.translation() - T.translation();
    const Vec3 phi = so3_log(perturbed.rotation() * T.rotation().conjugate());
    EXPECT_LE(rho.cwiseAbs().maxCoeff(), prior.scaled_translation_sigma() + 1e-12);
    EXPECT_LE(phi.cwiseAbs().maxCoeff(), prior.scaled_rotation_sigma() + 1e-9);
    second.head<3>() += rho.cwiseAbs2() / std::pow(prior.scaled_translation_sigma(), 2);
    second.tail<3>() += phi.cwiseAbs2() / std::pow(prior.scaled_rotation_sigma(), 2);
  }
  // N(0, 1) bounded at 1 has variance 1 - 2 phi(1) / (2 Phi(1) - 1) = 1 - 2 (0.241971) / 0.682689 = 0.291125.
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(second(k) / draws, 0.291125, 0.01) << "component " << k;
}

TEST(ExtrinsicPerturbation, NoPerturbationAtAlphaZero) {
  std::mt19937_64 rng(1);
  const SE3 T = toy_extrinsic();
  const SE3 same = sample_perturbed_extrinsic(T, PerturbationPrior{}, rng);
  EXPECT_EQ(same.translation(), T.translation());
  EXPECT_LT(same.rotation().angularDistance(T.rotation()), 1e-15);
}

TEST(ExtrinsicPerturbation, FileTangentAndLeftPerturbationAgree) {
  // Two routes from (rho, phi): straight to core's left perturbation, and through extrinsics.yaml's tangent.
  PerturbationPrior prior;
  prior.alpha = 0.06;
  prior.translation_sigma_m = 0.03;  // unequal sigmas, so the rotation block's frame matters
  const SE3 T(quat_from_rpy_deg(Vec3(5.0, -20.0, 70.0)), Vec3(3.5, -0.9, 0.5));
  Mat6 anisotropic = perturbation_covariance(prior);
  anisotropic(3, 3) *= 4.0;
  const Mat6 direct = perturbation_as_left_covariance(anisotropic, T);
  Mat6 file = anisotropic;
  const Mat3 R = T.rotation_matrix();
  file.bottomRightCorner<3, 3>() = R.transpose() * anisotropic.bottomRightCorner<3, 3>() * R;
  EXPECT_LT((covariance_in_left_tangent(T, file) - direct).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((perturbation_covariance_in_file_tangent(prior, T) - perturbation_covariance(prior)).cwiseAbs().maxCoeff(), 1e-15);
}

}  // namespace
}  // namespace mlidar
