// Extrinsic errors (thesis eq 4.31) and NEES against constructed errors.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/eval/calibration_metrics.hpp"

namespace mlidar::eval {
namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;
const SE3 kTruth(so3_exp(Vec3(0.1, -0.4, 2.0)), Vec3(0.5, -0.2, 1.1));

TEST(ExtrinsicError, KnownRotationAndTranslationErrors) {
  for (const double angle_deg : {0.0, 0.5, 3.0, 45.0, 170.0}) {
    const Vec3 axis = Vec3(1.0, 2.0, -0.5).normalized();
    const Vec3 shift(0.03, -0.04, 0.0);  // 5 cm
    // Perturb on either side: the geodesic angle is the same.
    const SE3 left(so3_exp(angle_deg * kRadiansPerDegree * axis) * kTruth.rotation(), kTruth.translation() + shift);
    const SE3 right(kTruth.rotation() * so3_exp(angle_deg * kRadiansPerDegree * axis), kTruth.translation() - shift);
    for (const SE3& estimate : {left, right}) {
      const ExtrinsicError error = extrinsic_error(kTruth, estimate, std::nullopt);
      EXPECT_NEAR(error.rotation_error_deg, angle_deg, 1e-9);
      EXPECT_NEAR(error.translation_error_m, 0.05, 1e-12);
      EXPECT_FALSE(error.nees.has_value());
    }
  }
}

TEST(ExtrinsicError, NeesOfAKnownErrorAndDiagonalCovariance) {
  // e_t = t_gt - t_est = (0.02, 0, 0), e_r = Log(R_est^T R_gt) = (0, 0, 0.01):
  // with sigma_t = 0.01 and sigma_r = 0.005, NEES = (0.02/0.01)^2 + (0.01/0.005)^2 = 8.
  const SE3 estimate(kTruth.rotation() * so3_exp(Vec3(0, 0, -0.01)), kTruth.translation() - Vec3(0.02, 0, 0));
  Vec6 sigmas;
  sigmas << 0.01, 0.01, 0.01, 0.005, 0.005, 0.005;
  const Mat6 covariance = sigmas.array().square().matrix().asDiagonal();
  const ExtrinsicError error = extrinsic_error(kTruth, estimate, covariance);
  ASSERT_TRUE(error.nees.has_value());
  EXPECT_NEAR(*error.nees, 8.0, 1e-6);
  EXPECT_TRUE(error.nees_within_95());
  const ExtrinsicError overconfident = extrinsic_error(kTruth, estimate, Mat6(covariance / 4.0));
  EXPECT_NEAR(*overconfident.nees, 32.0, 1e-5);
  EXPECT_FALSE(overconfident.nees_within_95());
  EXPECT_FALSE(extrinsic_error(kTruth, estimate, Mat6::Zero()).nees.has_value());  // not invertible
}

TEST(ExtrinsicError, ChiSquareBoundIsThe95PercentQuantile) {
  // Closed-form CDF of chi-square with 6 dof: 1 - exp(-x/2) (1 + x/2 + (x/2)^2 / 2).
  const double half = kChiSquare6Dof95 / 2.0;
  EXPECT_NEAR(1.0 - std::exp(-half) * (1.0 + half + half * half / 2.0), 0.95, 1e-12);
}

TEST(EvaluateCalibration, PerLidarInGroundTruthOrderAndMissingLidar) {
  io::Extrinsics gt;
  gt.lidars = {{"top", kTruth, std::nullopt}, {"left", SE3(), std::nullopt}};
  io::Extrinsics est;
  est.lidars = {{"left", SE3(so3_exp(Vec3(0, 2.0 * kRadiansPerDegree, 0)), Vec3::Zero()), std::nullopt}, {"top", kTruth, std::nullopt}};
  const auto errors = evaluate_calibration(gt, est, "est.yaml");
  ASSERT_EQ(errors.size(), 2U);
  EXPECT_EQ(errors[0].name, "top");
  EXPECT_NEAR(errors[0].rotation_error_deg, 0.0, 1e-9);
  EXPECT_EQ(errors[1].name, "left");
  EXPECT_NEAR(errors[1].rotation_error_deg, 2.0, 1e-9);

  est.lidars.pop_back();
  try {
    evaluate_calibration(gt, est, "est.yaml");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "est.yaml");
    EXPECT_EQ(e.field(), "lidars.top");
  }
}

}  // namespace
}  // namespace mlidar::eval
