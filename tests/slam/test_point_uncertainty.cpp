// Uncertainty-aware mapping's pieces (thesis sec 4.8): feature covariances
// against Monte Carlo, the registration weight, eq 4.30's voxel filter on
// cells worked by hand, the map keeping each point's covariance, and the
// weighted registration against constructed planes.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "mlidar/slam/point_uncertainty.hpp"
#include "mlidar/slam/scan_to_map.hpp"
#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {
namespace {

Mat3 diagonal(double xx, double yy, double zz) { return Vec3(xx, yy, zz).asDiagonal(); }

TEST(PointUncertainty, FeatureCovarianceMatchesMonteCarloInTheBaseFrame) {
  // p_base = Exp(xi) T_base_lidar (p_lidar + zeta), xi ~ N(0, Xi) (left, base frame), zeta ~ N(0, Z(p_lidar)).
  const SE3 T_base_lidar(so3_exp(Vec3(0.7, -0.1, 0.3)), Vec3(0.2, -0.5, -0.2));
  Vec6 sigmas;
  sigmas << 0.02, 0.01, 0.03, 0.01, 0.02, 0.015;
  Mat6 Xi = sigmas.cwiseAbs2().asDiagonal();
  Xi(0, 4) = Xi(4, 0) = 0.5 * sigmas(0) * sigmas(4);  // a correlation of translation and rotation
  const double range_sigma = 0.03, angular_sigma = 0.002;
  const Vec3 p_lidar(9.0, 4.0, -1.5);
  const Eigen::Vector3f p_base = (T_base_lidar * p_lidar).cast<float>();
  const std::vector<PointCovariance> computed = feature_covariances(std::span(&p_base, 1), {T_base_lidar, Xi}, range_sigma, angular_sigma);
  ASSERT_EQ(computed.size(), 1u);

  const Mat3 Z = lidar_point_noise(p_lidar, range_sigma, angular_sigma);
  const Mat6 L_xi = Xi.llt().matrixL();
  const Mat3 L_z = Z.llt().matrixL();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  constexpr int kSamples = 100000;
  std::vector<Vec3> samples(kSamples);
  Vec3 mean = Vec3::Zero();
  for (Vec3& y : samples) {
    Vec6 u;
    Vec3 v;
    for (int i = 0; i < 6; ++i) u(i) = normal(rng);
    for (int i = 0; i < 3; ++i) v(i) = normal(rng);
    const Vec3 noisy = p_lidar + L_z * v;
    y = SE3::exp(L_xi * u) * (T_base_lidar * noisy);
    mean += y / kSamples;
  }
  Mat3 sampled = Mat3::Zero();
  for (const Vec3& y : samples) sampled += (y - mean) * (y - mean).transpose() / (kSamples - 1);
  EXPECT_LT((computed[0].matrix() - sampled).norm() / sampled.norm(), 0.05) << computed[0].matrix() << "\nvs\n" << sampled;
}

TEST(PointUncertainty, CovarianceKeepsTheUpperTriangleAndProjectsOntoANormal) {
  Mat3 m;
  m << 0.04, 0.01, -0.02, 0.01, 0.09, 0.005, -0.02, 0.005, 0.01;
  const PointCovariance c = PointCovariance::from(m);
  EXPECT_LT((c.matrix() - m).norm(), 1e-8);
  EXPECT_NEAR(c.trace(), 0.14, 1e-8);
  const Vec3 n = Vec3(0.3, -0.4, 0.866).normalized();
  EXPECT_NEAR(c.along(n), n.dot(m * n), 1e-8);
}

TEST(PointUncertainty, WeightIsOneForACertainPointAndHalfWhenItsVarianceMatchesSigmaZero) {
  const Vec3 n = Vec3::UnitZ();
  EXPECT_EQ(uncertainty_weight(PointCovariance{}, n, 0.0025), 1.0);
  EXPECT_NEAR(uncertainty_weight(PointCovariance::from(diagonal(1.0, 1.0, 0.0025)), n, 0.0025), 0.5, 1e-6);
  // Only the variance along the normal counts: across it the point slides along the plane.
  EXPECT_NEAR(uncertainty_weight(PointCovariance::from(diagonal(1.0, 1.0, 0.0)), n, 0.0025), 1.0, 1e-12);
}

TEST(PointUncertainty, VoxelFilterMergesEachCubeByEquation430) {
  const double w = 1.0;
  const Mat3 Sa = diagonal(0.1, 0.05, 0.05), Sb = diagonal(0.2, 0.1, 0.1), Sc = diagonal(0.3, 0.2, 0.1);
  const std::vector<CovariantPoint> points = {
      {{0.2F, 0.2F, 0.2F}, PointCovariance::from(Sa)},                        // cube (0,0,0), tr 0.2
      {{1.5F, 0.1F, 0.1F}, PointCovariance::from(Sc)},                        // cube (1,0,0) alone, tr 0.6
      {{0.6F, 0.4F, 0.2F}, PointCovariance::from(Sb)},                        // cube (0,0,0), tr 0.4
      {{0.5F, 0.5F, 0.5F}, PointCovariance::from(diagonal(0.5, 0.4, 0.3))},   // cube (0,0,0), tr 1.2 >= w: no weight
      {{-0.5F, 0.5F, 0.5F}, PointCovariance::from(diagonal(0.5, 0.5, 0.5))},  // cube (-1,0,0), only uncertain: dropped
  };
  const std::vector<CovariantPoint> out = covariance_voxel_filter(points, 1.0, w);
  ASSERT_EQ(out.size(), 2u);
  // Cube (0,0,0): w_a = (1 - 0.2) / 1.4, w_b = (1 - 0.4) / 1.4 (they sum to 1).
  const double wa = 0.8 / 1.4, wb = 0.6 / 1.4;
  const Vec3 mean = wa * Vec3(0.2, 0.2, 0.2) + wb * Vec3(0.6, 0.4, 0.2);
  EXPECT_LT((out[0].point.cast<double>() - mean).norm(), 1e-6);
  EXPECT_LT((out[0].covariance.matrix() - (wa * wa * Sa + wb * wb * Sb)).norm(), 1e-7);
  // A cube of one point keeps it (weight 1).
  EXPECT_LT((out[1].point.cast<double>() - Vec3(1.5, 0.1, 0.1)).norm(), 1e-6);
  EXPECT_LT((out[1].covariance.matrix() - Sc).norm(), 1e-7);
}

TEST(PointUncertainty, VoxelFilterOfEqualCovariancesIsTheCentroid) {
  const PointCovariance same = PointCovariance::from(diagonal(0.01, 0.01, 0.01));
  const std::vector<CovariantPoint> points = {{{0.1F, 0.1F, 0.1F}, same}, {{0.3F, 0.1F, 0.1F}, same}, {{0.2F, 0.4F, 0.1F}, same}};
  const std::vector<CovariantPoint> out = covariance_voxel_filter(points, 0.5, 0.1);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_LT((out[0].point - Eigen::Vector3f(0.2F, 0.2F, 0.1F)).norm(), 1e-6F);
  EXPECT_NEAR(out[0].covariance.trace(), 0.03 / 3.0, 1e-8);  // 3 x (1/3)^2 x 0.01 per axis
  EXPECT_THROW(covariance_voxel_filter(points, 0.0, 0.1), std::invalid_argument);
}

// What the filter is for (sec 4.8.2): a frame's noisy points on a surface, merged per cube, lie closer to it, and
// the merged covariance still says how far (the normal's variance of the merged points against their spread).
TEST(PointUncertainty, VoxelFilterThinsANoisyPlaneAndItsCovarianceFollows) {
  const double sigma = 0.03;
  const PointCovariance noise = PointCovariance::from(diagonal(sigma * sigma, sigma * sigma, sigma * sigma));
  std::mt19937 engine(7);
  std::uniform_real_distribution<float> across(0.0F, 4.0F);
  std::normal_distribution<float> off_plane(0.0F, static_cast<float>(sigma));
  std::vector<CovariantPoint> points(8000);
  for (CovariantPoint& p : points) p = {{across(engine), across(engine), 0.1F + off_plane(engine)}, noise};
  const std::vector<CovariantPoint> merged = covariance_voxel_filter(points, 0.2, 0.1);
  // 4 x 4 m in 0.2 m cubes, the plane mid-way in z: 400 cubes of about 20 points, and a few single points beyond 3 sigma.
  ASSERT_GT(merged.size(), 390u);
  ASSERT_LT(merged.size(), 440u);
  std::vector<double> offsets;
  double normalized_sq = 0.0;
  for (const CovariantPoint& p : merged) {
    const double offset = p.point.z() - 0.1;
    offsets.push_back(std::abs(offset));
    normalized_sq += offset * offset / p.covariance.along(Vec3::UnitZ());
  }
  std::nth_element(offsets.begin(), offsets.begin() + offsets.size() / 2, offsets.end());
  // The typical merged point lies several times closer to the plane than the noise (median of |N(0, 1)| is 0.67) ...
  EXPECT_LT(offsets[offsets.size() / 2], 0.67 * sigma / 3.0);
  // ... and the covariance it carries says so: its normalized offsets have variance 1 when honest.
  const double variance = normalized_sq / static_cast<double>(merged.size());
  EXPECT_GT(variance, 0.7);
  EXPECT_LT(variance, 1.4);
}

TEST(PointUncertainty, VoxelFilterKeepsTheLidarOfEachCubesHeaviestPoint) {
  const double w = 1.0;
  const std::vector<CovariantPoint> points = {
      {{0.2F, 0.2F, 0.2F}, PointCovariance::from(diagonal(0.2, 0.1, 0.1)), 0},  // cube (0,0,0), weight 0.6
      {{0.6F, 0.4F, 0.2F}, PointCovariance::from(diagonal(0.1, 0.0, 0.0)), 2},  // cube (0,0,0), weight 0.9: the heaviest
      {{1.5F, 0.1F, 0.1F}, PointCovariance::from(diagonal(0.1, 0.1, 0.1)), 1},  // cube (1,0,0), alone
      {{1.6F, 0.1F, 0.1F}, PointCovariance::from(diagonal(0.1, 0.1, 0.1)), 0},  // same weight, later: the first is kept
  };
  const std::vector<CovariantPoint> out = covariance_voxel_filter(points, 1.0, w);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].source, 2);
  EXPECT_EQ(out[1].source, 1);
}

TEST(PointUncertainty, MapKeepsEachPointsLidarBesideItThroughRemoval) {
  VoxelMap map(1.0, 2);
  // Points at x = 0.5 + i (one voxel each, two per voxel at most) seen by LiDAR i % 3; a third point of a voxel is refused.
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint8_t> sources;
  for (int i = 0; i < 10; ++i)
    for (int k = 0; k < 3; ++k) {
      points.emplace_back(0.5F + static_cast<float>(i), 0.1F * static_cast<float>(k), 0.5F);
      sources.push_back(static_cast<std::uint8_t>((i + k) % 3));
    }
  map.add(points, sources);
  map.add(std::vector<Eigen::Vector3f>{{20.5F, 0.5F, 0.5F}});  // without a source
  map.remove_far(Eigen::Vector3f(0.0F, 0.0F, 0.0F), 5.2);      // keeps x = 0.5 .. 4.5
  const std::vector<Eigen::Vector3f> kept = map.points();
  const std::vector<std::uint8_t> kept_sources = map.sources();
  ASSERT_EQ(kept.size(), 10u);  // 5 voxels x 2 points
  ASSERT_EQ(kept_sources.size(), kept.size());
  for (std::size_t j = 0; j < kept.size(); ++j) {
    const int i = static_cast<int>(std::floor(kept[j].x()));
    const int k = static_cast<int>(std::lround(kept[j].y() / 0.1F));
    EXPECT_LT(k, 2) << "the third point of a voxel was refused";
    EXPECT_EQ(kept_sources[j], (i + k) % 3) << j;
  }
  EXPECT_THROW(map.add(points, std::vector<std::uint8_t>(2, 0)), std::invalid_argument);
}

TEST(PointUncertainty, MapKeepsEachPointsCovarianceBesideIt) {
  VoxelMap map(1.0, 4);
  const std::vector<Eigen::Vector3f> plain = {{0.1F, 0.1F, 0.1F}, {5.2F, 0.1F, 0.1F}};
  map.add(plain);
  const std::vector<Eigen::Vector3f> points = {{0.2F, 0.2F, 0.2F}, {3.5F, 0.5F, 0.5F}, {0.3F, 0.3F, 0.3F}};
  const std::vector<PointCovariance> covariances = {PointCovariance::from(diagonal(1, 1, 1)), PointCovariance::from(diagonal(2, 2, 2)),
                                                    PointCovariance::from(diagonal(3, 3, 3))};
  map.add(points, covariances);
  const std::vector<Eigen::Vector3f> all = map.points();
  const std::vector<PointCovariance> all_covariances = map.covariances();
  ASSERT_EQ(all.size(), 5u);
  ASSERT_EQ(all_covariances.size(), 5u);
  const auto expected_trace = [](const Eigen::Vector3f& p) {
    if (p.x() == 0.2F) return 3.0;
    if (p.x() == 3.5F) return 6.0;
    if (p.x() == 0.3F) return 9.0;
    return 0.0;  // added without one
  };
  for (std::size_t i = 0; i < all.size(); ++i) EXPECT_NEAR(all_covariances[i].trace(), expected_trace(all[i]), 1e-6) << i;
  map.remove_far({0.0F, 0.0F, 0.0F}, 4.0);  // the voxel at x = 5 goes
  EXPECT_EQ(map.points().size(), 4u);
  EXPECT_EQ(map.covariances().size(), 4u);
  EXPECT_THROW(map.add(points, std::span(covariances).first(2)), std::invalid_argument);
}

/// A plane map of the floor z = 0 and the walls x = 6, y = 6 (a corner), 0.1 m grid.
VoxelMap corner_map() {
  VoxelMap map(1.0, 400);  // room for every grid point of a voxel
  std::vector<Eigen::Vector3f> points;
  for (int i = -30; i <= 55; ++i)
    for (int j = -30; j <= 55; ++j) {
      const float a = 0.1F * static_cast<float>(i), b = 0.1F * static_cast<float>(j);
      points.emplace_back(a, b, 0.0F);
      if (b >= 0.0F && b <= 3.0F) {
        points.emplace_back(6.0F, a, b);
        points.emplace_back(a, 6.0F, b);
      }
    }
  map.add(points);
  return map;
}

/// Samples of the corner's three planes (one in 9 of the map's grid), offset by `shift`.
std::vector<Eigen::Vector3f> corner_samples(const Eigen::Vector3f& shift, float phase) {
  std::vector<Eigen::Vector3f> out;
  for (int i = -8; i <= 16; ++i)
    for (int j = -8; j <= 16; ++j) {
      const float a = 0.3F * static_cast<float>(i) + phase, b = 0.3F * static_cast<float>(j) + phase;
      out.push_back(Eigen::Vector3f(a, b, 0.0F) + shift);
      if (b > 0.2F && b < 2.8F) {
        out.push_back(Eigen::Vector3f(6.0F, a, b) + shift);
        out.push_back(Eigen::Vector3f(a, 6.0F, b) + shift);
      }
    }
  return out;
}

TEST(PointUncertainty, ZeroCovariancesGiveTheUnweightedRegistrationBitForBit) {
  const VoxelMap planes = corner_map(), edges(1.0, 10);
  const std::vector<Eigen::Vector3f> queries = corner_samples({0.0F, 0.0F, 0.0F}, 0.05F);
  const SE3 start(so3_exp(Vec3(0.01, -0.01, 0.02)), Vec3(0.1, -0.05, 0.04));
  const RegistrationConfig config;
  const RegistrationResult plain = register_scan_to_map({}, queries, edges, planes, start, 0.5, config);
  const std::vector<PointCovariance> zeros(queries.size());
  const QueryCovariances covariances{{}, zeros, 0.05};
  const RegistrationResult weighted = register_scan_to_map({}, queries, edges, planes, start, 0.5, config, nullptr, &covariances);
  EXPECT_EQ(plain.T_world_base.log(), weighted.T_world_base.log());
  EXPECT_EQ(plain.hessian, weighted.hessian);
  EXPECT_EQ(plain.iterations, weighted.iterations);
}

TEST(PointUncertainty, UncertainPointsOfAWrongExtrinsicBarelyMoveTheRegistration) {
  // Half the features come through a wrong extrinsic (shifted 5 cm on each axis): unweighted they pull the pose
  // half-way; with their doubt (1 m^2 per axis against the others' certain 0) they barely count.
  const VoxelMap planes = corner_map(), edges(1.0, 10);
  std::vector<Eigen::Vector3f> queries = corner_samples({0.0F, 0.0F, 0.0F}, 0.05F);
  const std::size_t certain = queries.size();
  const std::vector<Eigen::Vector3f> shifted = corner_samples({0.05F, 0.05F, 0.05F}, 0.1F);
  queries.insert(queries.end(), shifted.begin(), shifted.end());
  std::vector<PointCovariance> doubt(queries.size());
  for (std::size_t i = certain; i < queries.size(); ++i) doubt[i] = PointCovariance::from(diagonal(1.0, 1.0, 1.0));
  const RegistrationConfig config;
  const RegistrationResult plain = register_scan_to_map({}, queries, edges, planes, SE3::identity(), 0.5, config);
  const QueryCovariances covariances{{}, doubt, 0.05};
  const RegistrationResult weighted = register_scan_to_map({}, queries, edges, planes, SE3::identity(), 0.5, config, nullptr, &covariances);
  EXPECT_GT(plain.T_world_base.translation().norm(), 0.03);  // about half of 0.087 m
  EXPECT_LT(weighted.T_world_base.translation().norm(), 0.002);
}

}  // namespace
}  // namespace mlidar::slam
