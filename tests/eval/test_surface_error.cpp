// A map against true surfaces: the distance along the nearest sample's normal
// and its normalized error under each point's covariance, on a constructed
// plane where both are known by hand, and on draws from the covariances
// themselves (honest covariances: variance ~1, ~95 % inside the bound).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/eval/surface_error.hpp"

namespace mlidar::eval {
namespace {

/// The plane z = 0 sampled every 0.1 m over [-5, 5]^2, normals +z.
io::SurfaceSamples floor_samples() {
  io::SurfaceSamples samples;
  for (int i = -50; i <= 50; ++i)
    for (int j = -50; j <= 50; ++j) {
      samples.points.emplace_back(0.1F * i, 0.1F * j, 0.0F);
      samples.normals.emplace_back(0.0F, 0.0F, 1.0F);
    }
  return samples;
}

io::UpperCovariance diagonal(float xx, float yy, float zz) { return {xx, 0.0F, 0.0F, yy, 0.0F, zz}; }

TEST(SurfaceError, DistanceAlongTheNormalAndItsNormalizedErrorByHand) {
  // Heights 0.02 and -0.06 m, sigma_z 0.02 and 0.03 m: e = 1 and -2; x and y spread does not count.
  const std::vector<Eigen::Vector3f> points = {{0.33F, 1.21F, 0.02F}, {-2.04F, 0.5F, -0.06F}, {0.0F, 0.0F, 0.9F}};
  const std::vector<io::UpperCovariance> covariances = {diagonal(1.0F, 1.0F, 4e-4F), diagonal(0.5F, 0.0F, 9e-4F),
                                                        diagonal(1e-4F, 1e-4F, 1e-4F)};
  const SurfaceError error = surface_error(points, covariances, floor_samples(), {.max_distance_m = 0.5});
  EXPECT_EQ(error.points, 3u);
  EXPECT_EQ(error.matched, 2u);  // 0.9 m above the floor: not matched
  EXPECT_NEAR(error.distance_m.mean, 0.04, 1e-6);
  EXPECT_NEAR(error.distance_m.max, 0.06, 1e-6);
  EXPECT_NEAR(error.signed_mean_m, -0.02, 1e-6);  // (0.02 - 0.06) / 2
  ASSERT_TRUE(error.normalized.has_value());
  EXPECT_EQ(error.normalized->count, 2u);
  EXPECT_NEAR(error.normalized->mean, -0.5, 1e-4);
  EXPECT_NEAR(error.normalized->variance, 2.5, 1e-3);  // (1 + 4) / 2
  EXPECT_NEAR(error.normalized->inside_95, 0.5, 1e-12);
  EXPECT_FALSE(surface_error(points, std::nullopt, floor_samples()).normalized.has_value());
}

TEST(SurfaceError, PointsDrawnFromTheirCovariancesAreHonest) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-4.0, 4.0), sigma(0.005, 0.05);
  std::vector<Eigen::Vector3f> points;
  std::vector<io::UpperCovariance> covariances;
  for (int i = 0; i < 20000; ++i) {
    const double s = sigma(rng);
    points.emplace_back(static_cast<float>(uniform(rng)), static_cast<float>(uniform(rng)), static_cast<float>(s * normal(rng)));
    covariances.push_back(diagonal(0.01F, 0.01F, static_cast<float>(s * s)));
  }
  const SurfaceError honest = surface_error(points, covariances, floor_samples());
  ASSERT_EQ(honest.matched, points.size());
  EXPECT_NEAR(honest.normalized->variance, 1.0, 0.04);
  EXPECT_NEAR(honest.normalized->mean, 0.0, 0.03);
  EXPECT_NEAR(honest.normalized->inside_95, 0.95, 0.01);
  for (io::UpperCovariance& c : covariances) c[5] *= 4.0F;  // twice the sigma: variance 1/4
  EXPECT_NEAR(surface_error(points, covariances, floor_samples()).normalized->variance, 0.25, 0.01);
}

TEST(SurfaceError, RefusesMismatchedInput) {
  const std::vector<Eigen::Vector3f> points = {{0.0F, 0.0F, 0.0F}};
  EXPECT_THROW(surface_error(points, std::vector<io::UpperCovariance>{}, floor_samples()), std::invalid_argument);
  EXPECT_THROW(surface_error(points, std::nullopt, io::SurfaceSamples{}), std::invalid_argument);
  EXPECT_THROW(surface_error(points, std::nullopt, floor_samples(), {.max_distance_m = 0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::eval
