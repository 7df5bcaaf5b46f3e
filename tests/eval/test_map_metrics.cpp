// Mean map entropy and plane variance: closed forms, brute force, invariances.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "mlidar/eval/map_metrics.hpp"

namespace mlidar::eval {
namespace {

std::vector<Eigen::Vector3f> gaussian_cloud(std::size_t count, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0F, static_cast<float>(sigma));
  std::vector<Eigen::Vector3f> points(count);
  for (auto& point : points) point = {normal(rng), normal(rng), normal(rng)};
  return points;
}

TEST(MapMetrics, IsotropicGaussianMatchesClosedForm) {
  // A radius that covers the whole cloud makes Sigma(p) the sample covariance of
  // N(0, sigma^2 I) for every p: H = 1/2 ln((2 pi e)^3 sigma^6) = 3/2 ln(2 pi e sigma^2).
  // Sampling spread of 1/2 ln|S| with N = 4000: sqrt(6 / N) / 2 ~ 0.02; tolerance 3x.
  const double sigma = 0.5;
  const auto cloud = gaussian_cloud(4000, sigma, 21);
  const MapMetrics metrics = compute_map_metrics(cloud, {.radius = 100.0, .min_neighbors = 5});
  const double closed_form = 1.5 * std::log(2.0 * std::numbers::pi * std::numbers::e * sigma * sigma);
  EXPECT_EQ(metrics.points_used, 4000U);
  EXPECT_NEAR(metrics.mean_map_entropy, closed_form, 0.06);
}

TEST(MapMetrics, MatchesBruteForceNeighbourhoods) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0F, 3.0F);
  std::vector<Eigen::Vector3f> cloud(1500);
  for (auto& point : cloud) point = {u(rng), u(rng), u(rng) / 3.0F};
  const MapMetricsOptions options{.radius = 0.4, .min_neighbors = 6};
  double sum_entropy = 0.0;
  double sum_plane = 0.0;
  std::size_t used = 0;
  for (const auto& p : cloud) {  // O(N^2) reference with a two-pass covariance
    std::vector<Eigen::Vector3d> near;
    for (const auto& q : cloud) {
      if ((q - p).squaredNorm() <= 0.4F * 0.4F) near.push_back(q.cast<double>());
    }
    if (near.size() < options.min_neighbors) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& q : near) mean += q;
    mean /= static_cast<double>(near.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto& q : near) covariance += (q - mean) * (q - mean).transpose();
    covariance /= static_cast<double>(near.size() - 1);
    sum_entropy += 0.5 * std::log((2.0 * std::numbers::pi * std::numbers::e * covariance).determinant());
    sum_plane += Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues()(0);
    ++used;
  }
  const MapMetrics metrics = compute_map_metrics(cloud, options);
  ASSERT_GT(used, 1000U);
  EXPECT_EQ(metrics.points_used, used);
  EXPECT_NEAR(metrics.mean_map_entropy, sum_entropy / static_cast<double>(used), 1e-6);
  EXPECT_NEAR(metrics.mean_plane_variance, sum_plane / static_cast<double>(used), 1e-9);
}

TEST(MapMetrics, NoisyPlaneGivesItsNoiseVariance) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0F, 10.0F);
  std::normal_distribution<float> noise(0.0F, 0.01F);
  std::vector<Eigen::Vector3f> cloud(20000);
  for (auto& point : cloud) point = {u(rng), u(rng), noise(rng)};
  const MapMetrics metrics = compute_map_metrics(cloud, {.radius = 0.5, .min_neighbors = 10});
  EXPECT_NEAR(metrics.mean_plane_variance, 1e-4, 5e-6);
}

TEST(MapMetrics, ScalingByKAddsThreeLnK) {
  // H(kX) = H(X) + 3 ln k in 3D, when the radius scales with the cloud; rigid motion changes nothing.
  const auto cloud = gaussian_cloud(3000, 1.0, 4);
  const MapMetrics base = compute_map_metrics(cloud, {.radius = 0.8, .min_neighbors = 5});
  std::vector<Eigen::Vector3f> scaled;
  const Eigen::Matrix3f rotation = Eigen::AngleAxisf(0.7F, Eigen::Vector3f(1, 1, 0).normalized()).toRotationMatrix();
  for (const auto& p : cloud) scaled.push_back(2.0F * (rotation * p) + Eigen::Vector3f(5, -3, 1));
  const MapMetrics big = compute_map_metrics(scaled, {.radius = 1.6, .min_neighbors = 5});
  EXPECT_EQ(big.points_used, base.points_used);
  EXPECT_NEAR(big.mean_map_entropy, base.mean_map_entropy + 3.0 * std::log(2.0), 1e-4);
}

TEST(MapMetrics, SparseAndNonFinitePointsAreSkipped) {
  std::vector<Eigen::Vector3f> cloud = {{0, 0, 0}, {10, 0, 0}, {std::numeric_limits<float>::quiet_NaN(), 0, 0}};
  const MapMetrics metrics = compute_map_metrics(cloud);
  EXPECT_EQ(metrics.points, 3U);
  EXPECT_EQ(metrics.points_used, 0U);
  EXPECT_TRUE(std::isnan(metrics.mean_map_entropy));
  EXPECT_THROW(compute_map_metrics(cloud, {.radius = 0.0}), std::invalid_argument);
  EXPECT_THROW(compute_map_metrics(cloud, {.radius = 1.0, .min_neighbors = 3}), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::eval
