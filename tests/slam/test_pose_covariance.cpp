// Pose covariance of the odometry (slam/pose_covariance.hpp) on constructed
// registrations: the information form by hand, the held direction left to the
// prior, and the growth along a run (random walk; linear in a held direction
// or a run of lost frames).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mlidar/slam/pose_covariance.hpp"

namespace mlidar::slam {
namespace {

constexpr double kSigma2 = 1e-4;  // residual variance per row, m^2

RegistrationResult registration_with(const Vec6& hessian_diagonal) {
  RegistrationResult r;
  r.hessian = hessian_diagonal.asDiagonal();
  r.residuals_m.assign(106, 0.01f);  // 106 matches of 1 cm: sigma^2 = 100 * 1e-4 / 100
  r.residuals_m.push_back(std::numeric_limits<float>::quiet_NaN());
  return r;
}

FrameResult registered(const RegistrationResult& r) {
  FrameResult f;
  f.registration = r;
  return f;
}

TEST(PoseCovariance, ResidualVarianceSkipsUnmatchedAndCountsSixUnknowns) {
  const RegistrationResult r = registration_with(Vec6::Ones());
  EXPECT_NEAR(registration_residual_variance(r), 106 * 1e-4 / 100.0, 1e-9);
  RegistrationResult few;
  few.residuals_m.assign(6, 0.1f);
  EXPECT_EQ(registration_residual_variance(few), 0.0);
}

TEST(PoseCovariance, RegistrationCovarianceIsTheInverseOfMeasurementPlusPriorInformation) {
  const MotionPriorSigma prior{0.1, 0.05};
  Vec6 h;
  h << 1e3, 2e3, 5e2, 4e4, 3e4, 1e4;
  const Mat6 covariance = registration_covariance(h.asDiagonal(), kSigma2, Vec3::Zero(), prior);
  for (int k = 0; k < 6; ++k) {
    const double sigma_prior = k < 3 ? prior.translation_m : prior.rotation_rad;
    EXPECT_NEAR(covariance(k, k), 1.0 / (h(k) / kSigma2 + 1.0 / (sigma_prior * sigma_prior)), 1e-15) << k;
  }
  EXPECT_LT((covariance - Mat6(covariance.diagonal().asDiagonal())).norm(), 1e-18);
  // Nothing matched: the prediction alone.
  const Mat6 none = registration_covariance(h.asDiagonal(), 0.0, Vec3::Zero(), prior);
  EXPECT_NEAR(none(0, 0), prior.translation_m * prior.translation_m, 1e-15);
  EXPECT_NEAR(none(5, 5), prior.rotation_rad * prior.rotation_rad, 1e-15);
}

TEST(PoseCovariance, AHeldTranslationKeepsThePriorsVarianceAlongIt) {
  // A corridor along world x: H observes x too (floor, walls), but the registration kept x at the prediction.
  const MotionPriorSigma prior{0.1, 0.05};
  const Mat6 H = Vec6::Constant(1e4).asDiagonal();
  const Vec3 w = Vec3(1.0, 0.0, 0.02).normalized();
  const Mat6 covariance = registration_covariance(H, kSigma2, w, prior);
  EXPECT_NEAR(w.dot(covariance.topLeftCorner<3, 3>() * w), prior.translation_m * prior.translation_m, 1e-12);
  EXPECT_NEAR(covariance(1, 1), 1.0 / (1e4 / kSigma2 + 100.0), 1e-15);  // y unaffected
  EXPECT_LT(covariance(4, 4), 1e-8);                                    // the rotations stay measured
}

TEST(PoseCovariance, GrowsAsARandomWalkAndLinearlyAlongAHeldDirection) {
  PoseCovarianceChain chain;
  const RegistrationResult r = registration_with(Vec6::Constant(1e4));
  EXPECT_EQ(chain.add(registered(r), true).norm(), 0.0);  // the first frame defines the world
  const Mat6 one = chain.add(registered(r), false);
  const Mat6 two = chain.add(registered(r), false);
  EXPECT_LT((two - 2.0 * one).norm(), 1e-12 * one.norm());  // independent registrations add up

  RegistrationResult held = r;
  held.degenerate = true;
  held.weak_translation = Vec3::UnitX();
  const MotionPriorSigma prior;
  const int n = 20;
  double x = 0.0;
  for (int k = 0; k < n; ++k) x = chain.add(registered(held), false)(0, 0);
  // After n held frames: (n sigma_t)^2 along x on top of what came before (a persisting velocity error).
  EXPECT_NEAR(x - two(0, 0), n * n * prior.translation_m * prior.translation_m, 0.01 * n * n * prior.translation_m * prior.translation_m);
  const Mat6 now = chain.add(registered(held), false);
  EXPECT_GT(now(2, 2), 0.05 * 0.05 * n * n * prior.translation_m * prior.translation_m * 0.5);  // the cone around w
  EXPECT_LT(now(2, 2), now(0, 0) * 0.01);
}

TEST(PoseCovariance, LostFramesAddThePredictionAndGrowLinearlyInARow) {
  PoseCovarianceChain chain;
  const RegistrationResult r = registration_with(Vec6::Constant(1e4));
  chain.add(registered(r), true);
  FrameResult lost = registered(r);
  lost.trust = Trust::kLost;
  const MotionPriorSigma prior;
  Mat6 c;
  for (int k = 0; k < 3; ++k) c = chain.add(lost, false);
  EXPECT_NEAR(c(0, 0), 9.0 * prior.translation_m * prior.translation_m, 1e-12);
  EXPECT_NEAR(c(3, 3), 9.0 * prior.rotation_rad * prior.rotation_rad, 1e-12);
  FrameResult suspect = registered(r);
  suspect.trust = Trust::kAmbiguous;
  const Mat6 after = chain.add(suspect, false);
  EXPECT_GT(after(0, 0) - c(0, 0), prior.translation_m * prior.translation_m);  // inflated by a prediction's worth
}

}  // namespace
}  // namespace mlidar::slam
