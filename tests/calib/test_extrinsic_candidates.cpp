// Refinement arithmetic (thesis 3.4.3.2-3.4.3.3): the overlap factor against
// analytic point sets, the information transform against a finite-difference
// map of the perturbation, and the best-candidate mean against a known X
// with injected high-error outliers.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/calib/extrinsic_candidates.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

const SE3 kTruth(so3_exp(Vec3(0.7, -0.1, 0.2)), Vec3(0.1, -0.48, -0.22));

Vec3 gaussian3(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return {n(rng), n(rng), n(rng)};
}

/// Unit grid x in [x0, x0 + n), y in [0, 4), z = 0.
std::vector<Eigen::Vector3f> grid(int x0, int n) {
  std::vector<Eigen::Vector3f> points;
  for (int x = x0; x < x0 + n; ++x)
    for (int y = 0; y < 4; ++y) points.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0F);
  return points;
}

TEST(OverlapFactor, AnalyticSets) {
  const auto a = grid(0, 10);
  EXPECT_DOUBLE_EQ(overlap_factor(a, a, 0.1), 1.0);
  // b overlaps the second half of a: |S_a| / |P_a| = 1/2, |S_b| / |P_b| = 1/2 (eq 3.14).
  EXPECT_DOUBLE_EQ(overlap_factor(a, grid(5, 10), 0.1), 0.25);
  // Shifted by 0.5 in z: no point within 0.4, every point within 0.6.
  auto lifted = a;
  for (auto& p : lifted) p.z() += 0.5F;
  EXPECT_DOUBLE_EQ(overlap_factor(a, lifted, 0.4), 0.0);
  EXPECT_DOUBLE_EQ(overlap_factor(a, lifted, 0.6), 1.0);
  EXPECT_DOUBLE_EQ(overlap_factor(a, {}, 1.0), 0.0);
  auto with_nan = a;
  with_nan.emplace_back(std::numeric_limits<float>::quiet_NaN(), 0.0F, 0.0F);
  EXPECT_DOUBLE_EQ(overlap_factor(with_nan, a, 0.1), 1.0);
}

TEST(ExtrinsicInformation, MatchesThePerturbationMap) {
  // e = M d to first order, so e^T I_e e = d^T H d / sigma^2 for small d.
  std::mt19937_64 rng(7);
  const SE3 T_world_base(so3_exp(Vec3(0.2, 0.4, -1.1)), Vec3(5.0, -3.0, 1.0));
  std::normal_distribution<double> n(0.0, 1.0);
  Mat6 A;
  for (int i = 0; i < 36; ++i) A(i / 6, i % 6) = n(rng);
  const Mat6 H = A * A.transpose() + Mat6::Identity();
  const double variance = 0.02 * 0.02;
  const Mat6 info = extrinsic_information(H, variance, T_world_base, kTruth);
  for (int trial = 0; trial < 5; ++trial) {
    Vec6 d;
    d << gaussian3(rng, 1e-5), gaussian3(rng, 1e-5);
    const SE3 T_world_target = T_world_base * kTruth;
    const SE3 X = T_world_base.inverse() * SE3::exp(d) * T_world_target;
    Vec6 e;
    e << X.translation() - kTruth.translation(), so3_log(kTruth.rotation().conjugate() * X.rotation());
    const double expected = d.dot(H * d) / variance;
    EXPECT_NEAR(e.dot(info * e), expected, 1e-4 * expected);
  }
}

TEST(AverageBestCandidates, KeepsLowErrorCandidatesAndRecoversTruth) {
  std::mt19937_64 rng(3);
  std::vector<ExtrinsicCandidate> candidates;
  for (std::size_t k = 0; k < 40; ++k) {
    const bool outlier = k % 4 == 0;  // 10 gross outliers with large registration errors
    const double sigma_r = outlier ? 0.05 : 1e-3;
    const double sigma_t = outlier ? 0.2 : 0.005;
    ExtrinsicCandidate c;
    c.frame = k;
    c.T_base_target = SE3(kTruth.rotation() * so3_exp(gaussian3(rng, sigma_r)), kTruth.translation() + gaussian3(rng, sigma_t));
    c.error_m = (outlier ? 0.2 : 0.02) + 0.001 * static_cast<double>(k % 7);
    c.information = Mat6::Identity() * 1e6;
    candidates.push_back(c);
  }
  const CandidateAverage average = average_best_candidates(candidates, {.keep_fraction = 0.5, .min_keep = 5});
  ASSERT_EQ(average.kept.size(), 20u);
  for (const std::size_t i : average.kept) EXPECT_NE(candidates[i].frame % 4, 0u) << "an outlier was kept";
  EXPECT_LT(so3_log(kTruth.rotation().conjugate() * average.T_base_target.rotation()).norm(), 1e-3);
  EXPECT_LT((kTruth.translation() - average.T_base_target.translation()).norm(), 0.005);
  // Spread: the kept candidates' per-axis sample standard deviation ~ sigma.
  EXPECT_NEAR(std::sqrt(average.covariance_spread(0, 0)), 0.005, 0.002);
  EXPECT_NEAR(std::sqrt(average.covariance_spread(3, 3)), 1e-3, 4e-4);
  EXPECT_NEAR(average.covariance_icp(0, 0), 1.0 / (20.0 * 1e6), 1e-12);
  // The shared-bias term: the selection's per-axis sds on the diagonal, added to the rest.
  const CandidateSelection defaults;
  EXPECT_DOUBLE_EQ(std::sqrt(average.covariance_bias(2, 2)), defaults.bias_translation_sd_m);
  EXPECT_NEAR(std::sqrt(average.covariance_bias(4, 4)), deg_to_rad(defaults.bias_rotation_sd_deg), 1e-15);
  EXPECT_TRUE(average.covariance_bias.isDiagonal());
  EXPECT_TRUE(average.covariance.isApprox(average.covariance_spread + average.covariance_icp + average.covariance_bias));

  // The input order does not matter.
  std::vector<ExtrinsicCandidate> shuffled = candidates;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  const CandidateAverage again = average_best_candidates(shuffled, {.keep_fraction = 0.5, .min_keep = 5});
  EXPECT_LT((again.T_base_target.translation() - average.T_base_target.translation()).norm(), 1e-12);
  EXPECT_LT(so3_log(again.T_base_target.rotation().conjugate() * average.T_base_target.rotation()).norm(), 1e-12);
}

TEST(AverageBestCandidates, MinKeepAndEmptyInput) {
  std::vector<ExtrinsicCandidate> candidates(3);
  for (std::size_t k = 0; k < 3; ++k) candidates[k].frame = k;
  EXPECT_EQ(average_best_candidates(candidates, {.keep_fraction = 0.1, .min_keep = 5}).kept.size(), 3u);
  EXPECT_THROW(average_best_candidates({}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::calib

namespace mlidar::calib {
namespace {

/// A candidate that saw every direction but `weak` (a translation direction): there its value is `start`'s
/// and its information zero, elsewhere the truth plus noise of the stated sigma.
ExtrinsicCandidate degenerate_candidate(const SE3& start, const Vec3& weak, double sigma_t, double sigma_r, std::mt19937_64& rng) {
  const Vec3 w = weak.normalized();
  Vec3 t = kTruth.translation() + gaussian3(rng, sigma_t);
  t += w * w.dot(start.translation() - t);  // the start's component along w
  ExtrinsicCandidate c;
  c.T_base_target = SE3(kTruth.rotation() * so3_exp(gaussian3(rng, sigma_r)), t);
  c.degenerate = true;
  Mat6 information = Mat6::Zero();
  information.topLeftCorner<3, 3>() = (Mat3::Identity() - w * w.transpose()) / (sigma_t * sigma_t);
  information.bottomRightCorner<3, 3>() = Mat3::Identity() / (sigma_r * sigma_r);
  c.information = information;
  return c;
}

TEST(FuseByInformation, DegenerateCandidatesWithDifferentWeakDirectionsRecoverTheTruth) {
  std::mt19937_64 rng(11);
  const SE3 start(kTruth.rotation() * so3_exp(Vec3(0.01, 0.0, -0.02)), kTruth.translation() + Vec3(0.4, -0.3, 0.05));
  std::vector<ExtrinsicCandidate> candidates;
  // Most frames along the street (weak x), a few at a turn (weak y) and on a diagonal.
  for (int i = 0; i < 12; ++i) candidates.push_back(degenerate_candidate(start, Vec3::UnitX(), 0.005, 0.0005, rng));
  for (int i = 0; i < 3; ++i) candidates.push_back(degenerate_candidate(start, Vec3::UnitY(), 0.005, 0.0005, rng));
  for (int i = 0; i < 3; ++i) candidates.push_back(degenerate_candidate(start, Vec3(1.0, 1.0, 0.0), 0.005, 0.0005, rng));
  const InformationFusion fused = fuse_by_information(candidates, start);
  EXPECT_LT((fused.T_base_target.translation() - kTruth.translation()).norm(), 0.006);
  EXPECT_LT(rad_to_deg(fused.T_base_target.rotation().angularDistance(kTruth.rotation())), 0.02);
  // Each candidate is 40 cm off along its weak direction; their plain mean would be too.
  Vec3 mean = Vec3::Zero();
  for (const auto& c : candidates) mean += c.T_base_target.translation() / static_cast<double>(candidates.size());
  EXPECT_GT((mean - kTruth.translation()).norm(), 0.1);
  // x is seen by 6 of 18 candidates, y by 15, z by all: the weakest direction is x's.
  EXPECT_GT(std::abs(fused.weak_direction.x()), 0.9);
  EXPECT_GT(fused.translation_observability, 0.0);
  EXPECT_LT(fused.translation_observability, 0.5);
  // Noise as the information says: chi2 per degree of freedom near 1 (5 of 6 directions observed per candidate).
  EXPECT_GT(fused.chi2_per_dof, 0.4);
  EXPECT_LT(fused.chi2_per_dof, 1.6);
}

TEST(FuseByInformation, OneWeakDirectionSharedByAllStaysUnobservedAndSaysSo) {
  std::mt19937_64 rng(12);
  const SE3 start(kTruth.rotation(), kTruth.translation() + Vec3(0.4, 0.0, 0.0));
  std::vector<ExtrinsicCandidate> candidates;
  for (int i = 0; i < 10; ++i) candidates.push_back(degenerate_candidate(start, Vec3::UnitX(), 0.005, 0.0005, rng));
  const InformationFusion fused = fuse_by_information(candidates, start);
  EXPECT_LT(fused.translation_observability, 1e-6);
  EXPECT_GT(std::abs(fused.weak_direction.x()), 0.99);
  // Its variance along x is huge, so no bound on the covariance can call it calibrated.
  EXPECT_GT(fused.covariance(0, 0), 1.0);
  EXPECT_THROW(fuse_by_information({}, start), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::calib
