// Algorithm 1 (thesis Sec. 4.7.4) on constructed information matrices.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/QR>

#include "mlidar/calib/convergence_monitor.hpp"
#include "mlidar/core/rotation_average.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

const SE3 kTrueExtrinsic(so3_exp(Vec3(0.1, -0.2, 0.3)), Vec3(0.5, -0.2, 0.1));

/// A random orthonormal 6x6 basis (seeded): information = V diag(eigenvalues) V^T.
Mat6 random_basis(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Mat6 M;
  for (int i = 0; i < 36; ++i) M(i / 6, i % 6) = n(rng);
  return Eigen::HouseholderQR<Mat6>(M).householderQ();
}

Mat6 information_with(const Vec6& eigenvalues, const Mat6& basis) { return basis * eigenvalues.asDiagonal() * basis.transpose(); }

Mat6 information_with_min(double lambda_min, std::uint64_t seed) {
  Vec6 values;
  values << lambda_min, 200, 300, 400, 500, 600;
  return information_with(values, random_basis(seed));
}

TEST(ConvergenceMonitor, AcceptsJustAboveAndRejectsJustBelowLambdaCalib) {
  ConvergenceMonitor monitor({SE3(), SE3()});
  const SE3 estimate(so3_exp(Vec3(0.01, 0, 0)), Vec3(0.1, 0, 0));
  const WindowVerdict below = monitor.add_window(1, estimate, information_with_min(70.0 - 1e-6, 1));
  EXPECT_FALSE(below.accepted);
  EXPECT_NEAR(below.lambda_min, 70.0 - 1e-6, 1e-9);
  EXPECT_TRUE(monitor.lidar(1).T_base_lidar.translation().isZero());  // rejected: extrinsic unchanged
  const WindowVerdict above = monitor.add_window(1, estimate, information_with_min(70.0 + 1e-6, 2));
  EXPECT_TRUE(above.accepted);
  EXPECT_NEAR(above.lambda_min, 70.0 + 1e-6, 1e-9);
  EXPECT_NEAR((monitor.lidar(1).T_base_lidar.translation() - estimate.translation()).norm(), 0.0, 1e-15);
  EXPECT_EQ(monitor.lidar(1).accepted.size(), 1u);
  EXPECT_EQ(monitor.lidar(0).accepted.size(), 0u);
  EXPECT_EQ(monitor.lidar(1).windows, 2u);
}

TEST(ConvergenceMonitor, AConstrainedWindowThatHasNotSettledIsNotAccepted) {
  ConvergenceMonitor monitor({kTrueExtrinsic});
  const Mat6 information = information_with_min(100.0, 4);
  const WindowVerdict moving = monitor.add_window(0, kTrueExtrinsic, information, 1e-3, false);
  EXPECT_TRUE(moving.constrained);
  EXPECT_FALSE(moving.accepted);
  EXPECT_TRUE(monitor.lidar(0).accepted.empty());
  const WindowVerdict settled = monitor.add_window(0, kTrueExtrinsic, information, 1e-3, true);
  EXPECT_TRUE(settled.constrained && settled.accepted);
  EXPECT_EQ(monitor.lidar(0).accepted.size(), 1u);
  EXPECT_FALSE(monitor.add_window(0, kTrueExtrinsic, information_with_min(40.0, 5), 1e-3, true).constrained);
}

TEST(RobustInliers, DropsTheFarEstimatesAndKeepsAgreeingOnes) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.004);
  std::vector<Vec6> deviations;
  for (int i = 0; i < 20; ++i) deviations.push_back((Vec6() << noise(rng), noise(rng), noise(rng), 0, 0, 0).finished());
  for (int i = 0; i < 5; ++i) deviations.push_back((Vec6() << 0, 0.06 + 0.02 * i, 0, 0, 0, 0).finished());
  const Vec6 floor = Vec6::Constant(0.001);
  const std::vector<std::size_t> inliers = robust_inliers(deviations, 3.0, floor);
  // Every far one goes; a 3-sigma gate on three noisy axes may also drop a tail sample or two of the 20.
  EXPECT_GE(inliers.size(), 18u);
  for (const std::size_t i : inliers) EXPECT_LT(i, 20u);
  EXPECT_EQ(robust_inliers(deviations, 0.0, floor).size(), 25u);  // off
  // Identical estimates (MAD 0): the floor keeps every one.
  const std::vector<Vec6> identical(10, Vec6::Constant(0.01));
  EXPECT_EQ(robust_inliers(identical, 3.0, floor).size(), 10u);
}

TEST(ConvergenceMonitor, OutlyingAcceptedEstimatesAreLeftOutOfTheMean) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.003);
  const auto run = [&](double outlier_mads) {
    ConvergenceConfig config;
    config.outlier_mads = outlier_mads;
    ConvergenceMonitor monitor({kTrueExtrinsic}, config);
    rng.seed(11);
    for (int i = 0; i < 25; ++i) {
      const Vec3 t_error = i < 19 ? Vec3(noise(rng), noise(rng), noise(rng)) : Vec3(0.0, 0.1, 0.0);  // 6 windows 10 cm off in y
      monitor.add_window(0, SE3(kTrueExtrinsic.rotation(), kTrueExtrinsic.translation() + t_error), information_with_min(100.0, 40 + i));
    }
    EXPECT_EQ(monitor.lidar(0).mode, CalibrationMode::converged);
    return monitor.lidar(0);
  };
  const LidarCalibrationState plain = run(0.0);
  EXPECT_EQ(plain.outliers, 0u);
  EXPECT_GT((plain.T_base_lidar.translation() - kTrueExtrinsic.translation()).norm(), 0.02);  // 6 / 25 of 10 cm
  const LidarCalibrationState robust = run(3.0);
  EXPECT_EQ(robust.outliers, 6u);
  EXPECT_LT((robust.T_base_lidar.translation() - kTrueExtrinsic.translation()).norm(), 0.004);
}

TEST(ConvergenceMonitor, ConvergesAfterExactlyLCalibAcceptedWindows) {
  ConvergenceMonitor monitor({kTrueExtrinsic});
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 0.01);
  int accepted = 0;
  std::vector<SE3> good_estimates;  // the constructed inputs that must be accepted, for the expected mean below
  for (int window = 0; accepted < 25; ++window) {
    const bool good = window % 3 != 1;  // every third window is degenerate
    const SE3 estimate(so3_exp(Vec3(n(rng), n(rng), n(rng))) * kTrueExtrinsic.rotation(), kTrueExtrinsic.translation() + Vec3(n(rng), n(rng), n(rng)));
    if (good) good_estimates.push_back(estimate);
    const WindowVerdict v = monitor.add_window(0, estimate, information_with_min(good ? 90.0 : 40.0, 10 + window));
    EXPECT_EQ(v.accepted, good);
    accepted += good ? 1 : 0;
    EXPECT_EQ(v.converged_now, accepted == 25);
    EXPECT_EQ(monitor.lidar(0).mode, accepted == 25 ? CalibrationMode::converged : CalibrationMode::calibrating);
  }
  EXPECT_TRUE(monitor.all_converged());
  const SE3 converged = monitor.lidar(0).T_base_lidar;
  const WindowVerdict ignored = monitor.add_window(0, SE3(), information_with_min(1000.0, 99));
  EXPECT_FALSE(ignored.accepted);  // calibration has stopped
  EXPECT_EQ(monitor.lidar(0).T_base_lidar.translation(), converged.translation());
  // The expected mean and scatter from the 25 constructed estimates, written out here (not extrinsic_mean or
  // calibration_covariance): the translations' average; the rotations' geodesic mean by the fixed point
  // R <- Exp(mean_i Log(R_i R^-1)) R started at the truth; deviations [t_i - t_mean, Log(R_mean^-1 R_i)].
  ASSERT_EQ(good_estimates.size(), 25u);
  const double count = 25.0;
  Vec3 expected_t = Vec3::Zero();
  for (const SE3& T : good_estimates) expected_t += T.translation();
  expected_t /= count;
  Quat expected_R = kTrueExtrinsic.rotation();
  for (int iteration = 0; iteration < 100; ++iteration) {
    Vec3 step = Vec3::Zero();
    for (const SE3& T : good_estimates) step += so3_log(T.rotation() * expected_R.conjugate());
    expected_R = (so3_exp(step / count) * expected_R).normalized();
  }
  EXPECT_LT((monitor.lidar(0).T_base_lidar.translation() - expected_t).norm(), 1e-15);
  EXPECT_LT(so3_log(monitor.lidar(0).T_base_lidar.rotation() * expected_R.conjugate()).norm(), 1e-12);
  std::vector<Vec6> deviations;
  Mat6 scatter = Mat6::Zero();  // sample covariance, divisor n - 1
  for (const SE3& T : good_estimates) {
    deviations.push_back((Vec6() << T.translation() - expected_t, so3_log(expected_R.conjugate() * T.rotation())).finished());
    scatter += deviations.back() * deviations.back().transpose() / (count - 1.0);
  }
  // Integrated autocorrelation time, Geyer's initial positive sequence: rho_k the mean over the 6 axes of
  // sum_i d_i d_i+k / (n var), var = sum_i d_i^2 / n; tau = -1 + 2 sum_m (rho_2m + rho_2m+1) while the pair is > 0,
  // clamped to [1, n].
  Vec6 variance = Vec6::Zero();
  for (const Vec6& d : deviations) variance += d.cwiseAbs2() / count;
  const auto rho = [&](std::size_t lag) {
    double sum = 0.0;
    for (int axis = 0; axis < 6; ++axis) {
      double products = 0.0;
      for (std::size_t i = 0; i + lag < deviations.size(); ++i) products += deviations[i](axis) * deviations[i + lag](axis);
      sum += products / count / variance(axis);
    }
    return sum / 6.0;
  };
  double expected_tau = -1.0;
  for (std::size_t m = 0; 2 * m + 1 < deviations.size(); ++m) {
    const double pair = rho(2 * m) + rho(2 * m + 1);
    if (!(pair > 0.0)) break;
    expected_tau += 2.0 * pair;
  }
  expected_tau = std::clamp(expected_tau, 1.0, count);
  EXPECT_NEAR(monitor.lidar(0).covariance_parts.autocorrelation_time, expected_tau, 1e-12);
  // No residual variance given: Xi_calib is the scatter term alone, the
  // variance of the mean of 25 estimates (S tau / 25, tau ~ 1 for independent ones).
  EXPECT_TRUE(monitor.lidar(0).covariance.isApprox(scatter * expected_tau / count, 1e-12));
  EXPECT_TRUE(monitor.lidar(0).covariance_parts.windows.isZero());
  EXPECT_LT(monitor.lidar(0).covariance_parts.autocorrelation_time, 3.0);
  EXPECT_LT(monitor.lidar(0).covariance.diagonal().maxCoeff(), 3.0 * 4.0 * 0.01 * 0.01 / 25);
  EXPECT_GT(monitor.lidar(0).covariance.diagonal().minCoeff(), 0.25 * 0.01 * 0.01 / 25);
}

/// A monitor that needs 4 accepted windows, fed 4 identical ones (estimate kTrueExtrinsic, residual variance 1e-3).
ConvergenceMonitor converged_on_identical_windows(ConvergenceConfig config, const Mat6& information) {
  config.accepted_needed = 4;
  ConvergenceMonitor monitor({kTrueExtrinsic}, config);
  for (int window = 0; window < 4; ++window) monitor.add_window(0, kTrueExtrinsic, information, 1e-3);
  return monitor;
}

TEST(ConvergenceMonitor, WindowCovariancesEnterXiCalibWhenTheResidualVarianceIsGiven) {
  ConvergenceConfig config;
  config.min_autocorrelation_time = 5.0;
  const Mat6 information = information_with_min(100.0, 2);
  const ConvergenceMonitor monitor = converged_on_identical_windows(config, information);
  ASSERT_EQ(monitor.lidar(0).mode, CalibrationMode::converged);
  // Identical estimates: no scatter; Xi_calib is one window's sigma^2 Lambda^-1 in the local tangent, written out:
  // Lambda = V diag(100, 200, ..., 600) V^T, so Lambda^-1 = V diag(1/100, ..., 1/600) V^T; a left perturbation
  // Exp(d) T reads e = M d in [t additive, r local], M = [I, -[t]x; 0, R^T].
  const Mat6 basis = random_basis(2);
  const Vec6 inverse_eigenvalues = (Vec6() << 1.0 / 100, 1.0 / 200, 1.0 / 300, 1.0 / 400, 1.0 / 500, 1.0 / 600).finished();
  const Mat6 inverse_information = basis * inverse_eigenvalues.asDiagonal() * basis.transpose();
  const Vec3 t = kTrueExtrinsic.translation();
  Mat3 t_cross;
  t_cross << 0.0, -t.z(), t.y(),  //
      t.z(), 0.0, -t.x(),         //
      -t.y(), t.x(), 0.0;
  Mat6 left_to_local = Mat6::Zero();
  left_to_local.topLeftCorner<3, 3>() = Mat3::Identity();
  left_to_local.topRightCorner<3, 3>() = -t_cross;
  left_to_local.bottomRightCorner<3, 3>() = kTrueExtrinsic.rotation().toRotationMatrix().transpose();
  const Mat6 expected = left_to_local * (1e-3 * inverse_information) * left_to_local.transpose();
  EXPECT_TRUE(monitor.lidar(0).covariance.isApprox(expected, 1e-9));
  EXPECT_DOUBLE_EQ(monitor.lidar(0).covariance_parts.autocorrelation_time, 4.0);  // the floor 5 clamped to n
  EXPECT_THROW(ConvergenceMonitor({kTrueExtrinsic}, ConvergenceConfig{.min_autocorrelation_time = 0.5}), std::invalid_argument);
}

TEST(ConvergenceMonitor, SharedErrorFloorIsAddedPerAxis) {
  ConvergenceConfig config;
  config.bias_translation_sd_m = 0.015;
  config.bias_rotation_sd_deg = 0.1;
  const ConvergenceMonitor monitor = converged_on_identical_windows(config, information_with_min(100.0, 3));
  ASSERT_EQ(monitor.lidar(0).mode, CalibrationMode::converged);
  const CalibrationCovariance& parts = monitor.lidar(0).covariance_parts;
  Vec6 variance;
  variance << Vec3::Constant(0.015 * 0.015), Vec3::Constant(std::pow(0.1 * 3.141592653589793 / 180.0, 2));
  EXPECT_TRUE(parts.bias.isApprox(Mat6(variance.asDiagonal()), 1e-12));
  EXPECT_TRUE(monitor.lidar(0).covariance.isApprox(parts.spread + parts.windows + parts.bias, 1e-12));
  // Identical estimates: however many windows agree, the 1-sigma never drops below the floor.
  EXPECT_GE(monitor.lidar(0).covariance(0, 0), 0.015 * 0.015);
}

TEST(ExtrinsicMean, SymmetricSamplesGiveTheCentreAndTheAnalyticCovariance) {
  // 12 pairs Exp(+-d_j) R0, t0 +- e_j and the centre itself: mean (R0, t0) exactly,
  // covariance sum_j 2 [e_j; d_j][e_j; d_j]^T / (25 - 1).
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n(0.0, 0.05);
  std::vector<SE3> samples{kTrueExtrinsic};
  Mat6 expected = Mat6::Zero();
  for (int j = 0; j < 12; ++j) {
    Vec6 x;
    for (int i = 0; i < 6; ++i) x(i) = n(rng);
    for (const double s : {1.0, -1.0}) {
      samples.emplace_back(so3_exp(s * x.tail<3>()) * kTrueExtrinsic.rotation(), kTrueExtrinsic.translation() + s * x.head<3>());
    }
    expected += 2.0 * x * x.transpose();
  }
  expected /= 24.0;
  const ExtrinsicMean mean = extrinsic_mean(samples);
  EXPECT_LT(so3_log(mean.mean.rotation() * kTrueExtrinsic.rotation().conjugate()).norm(), 1e-12);
  EXPECT_LT((mean.mean.translation() - kTrueExtrinsic.translation()).norm(), 1e-15);
  EXPECT_TRUE(mean.covariance.isApprox(expected, 1e-10));
}

TEST(ExtrinsicMean, RandomSamplesSatisfyTheKarcherConditionAndMatchTheChordalMean) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 0.1);
  std::vector<SE3> samples;
  std::vector<Quat> rotations;
  for (int i = 0; i < 25; ++i) {
    samples.emplace_back(so3_exp(Vec3(n(rng), n(rng), n(rng))) * kTrueExtrinsic.rotation(), Vec3(n(rng), n(rng), n(rng)));
    rotations.push_back(samples.back().rotation());
  }
  const ExtrinsicMean mean = extrinsic_mean(samples);
  Vec3 rotation_sum = Vec3::Zero();
  Mat6 direct = Mat6::Zero();
  for (const SE3& T : samples) {
    Vec6 d;
    d << T.translation() - mean.mean.translation(), so3_log(T.rotation() * mean.mean.rotation().conjugate());
    rotation_sum += d.tail<3>();
    direct += d * d.transpose() / 24.0;
  }
  EXPECT_LT(rotation_sum.norm(), 1e-12);  // first-order optimality of the geodesic L2 mean
  EXPECT_TRUE(mean.covariance.isApprox(direct, 1e-12));
  EXPECT_LT(so3_log(mean.mean.rotation() * chordal_mean(rotations).conjugate()).norm(), 1e-3);
  EXPECT_THROW(extrinsic_mean({}), std::invalid_argument);
}

TEST(WeakDirections, NamesSingleAxesAndMixtures) {
  Vec6 planar;
  planar << 500, 500, 1e-3, 500, 500, 500;  // t_z unobservable (planar motion)
  const auto weak = weak_directions(planar.asDiagonal(), 70.0);
  ASSERT_EQ(weak.size(), 1u);
  EXPECT_EQ(weak[0].description, "translation z");
  EXPECT_NEAR(weak[0].eigenvalue, 1e-3, 1e-12);

  Vec6 two;
  two << 500, 500, 10, 500, 20, 500;  // t_z and rotation about y, weakest first
  const auto both = weak_directions(two.asDiagonal(), 70.0);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].description, "translation z");
  EXPECT_EQ(both[1].description, "rotation about y");
  EXPECT_TRUE(weak_directions(two.asDiagonal(), 5.0).empty());

  Vec6 mixed = Vec6::Zero();
  mixed(0) = -0.8;
  mixed(5) = 0.6;  // -0.8 t_x + 0.6 r_z, reported with the largest component positive
  EXPECT_EQ(describe_direction(mixed), "0.80 translation x - 0.60 rotation about z");
  // Built into an information matrix: the same words come back.
  Mat6 basis = Mat6::Identity();
  basis.col(0) = mixed;
  basis.col(5) = Vec6(0.6, 0, 0, 0, 0, 0.8);
  Vec6 values;
  values << 1.0, 300, 300, 300, 300, 300;
  const auto rotated = weak_directions(information_with(values, basis), 70.0);
  ASSERT_EQ(rotated.size(), 1u);
  EXPECT_EQ(rotated[0].description, "0.80 translation x - 0.60 rotation about z");
  EXPECT_NEAR(rotated[0].direction(0), 0.8, 1e-12);
}

TEST(ConvergenceMonitor, WeakDirectionsOfTheLastWindowAreReportedPerLidar) {
  ConvergenceMonitor monitor({SE3(), SE3()});
  Vec6 planar;
  planar << 500, 500, 2.0, 500, 500, 500;
  monitor.add_window(1, kTrueExtrinsic, planar.asDiagonal());
  ASSERT_EQ(monitor.lidar(1).weak.size(), 1u);
  EXPECT_EQ(monitor.lidar(1).weak[0].description, "translation z");
  EXPECT_TRUE(monitor.lidar(0).weak.empty());
  EXPECT_DOUBLE_EQ(monitor.lidar(1).last_lambda_min, 2.0);
}

TEST(ConvergenceMonitor, RestartReturnsToCalibratingWithAnEmptySet) {
  ConvergenceConfig config;
  config.accepted_needed = 3;
  ConvergenceMonitor monitor({SE3()}, config);
  for (int i = 0; i < 3; ++i) monitor.add_window(0, kTrueExtrinsic, information_with_min(100.0, 20 + i));
  ASSERT_EQ(monitor.lidar(0).mode, CalibrationMode::converged);
  monitor.restart(0);
  EXPECT_EQ(monitor.lidar(0).mode, CalibrationMode::calibrating);
  EXPECT_TRUE(monitor.lidar(0).accepted.empty());
  EXPECT_EQ(monitor.lidar(0).restarts, 1u);
  EXPECT_LT(so3_log(monitor.lidar(0).T_base_lidar.rotation() * kTrueExtrinsic.rotation().conjugate()).norm(), 1e-12);
  EXPECT_TRUE(monitor.add_window(0, kTrueExtrinsic, information_with_min(100.0, 30)).accepted);
}

TEST(ConvergenceMonitor, NonFiniteInputIsNeverAccepted) {
  ConvergenceMonitor monitor({SE3()});
  Mat6 info = information_with_min(100.0, 40);
  info(2, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(monitor.add_window(0, kTrueExtrinsic, info).accepted);
  EXPECT_THROW(ConvergenceMonitor({}), std::invalid_argument);
  EXPECT_THROW(monitor.add_window(3, kTrueExtrinsic, Mat6::Identity()), std::out_of_range);
}

}  // namespace
}  // namespace mlidar::calib
