// The map test of the LiDARs' agreement: two LiDARs' points on the same floor
// and walls, with 1 cm noise. Placed by right extrinsics, each LiDAR's points lie
// as near the other's planes as its own; one LiDAR's points moved by 10 cm (a
// wrong extrinsic) lie 10 cm off the other's planes: a ratio far above 3.
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/slam/map_consistency.hpp"

namespace mlidar::slam {
namespace {

/// Points on the floor z = 0 and the walls x = 0 and y = 0 of a 6 m room corner, 1 cm Gaussian noise off each
/// surface, `offset` added to all (the second LiDAR's misplacement).
std::vector<Eigen::Vector3f> corner(std::uint64_t seed, const Eigen::Vector3f& offset) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> along(0.2F, 6.0F);
  std::normal_distribution<float> noise(0.0F, 0.01F);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 400; ++i) {  // ~12 per m^2 on each surface, about as dense as the local map holds them
    points.push_back(Eigen::Vector3f(along(rng), along(rng), noise(rng)) + offset);
    points.push_back(Eigen::Vector3f(noise(rng), along(rng), along(rng)) + offset);
    points.push_back(Eigen::Vector3f(along(rng), noise(rng), along(rng)) + offset);
  }
  return points;
}

VoxelMap two_lidars(const Eigen::Vector3f& offset_of_second) {
  VoxelMap map(1.0, 60);
  const std::vector<Eigen::Vector3f> first = corner(1, Eigen::Vector3f::Zero()), second = corner(2, offset_of_second);
  map.add(first, std::vector<std::uint8_t>(first.size(), 0));
  map.add(second, std::vector<std::uint8_t>(second.size(), 1));
  return map;
}

TEST(MapConsistency, LidarsOnTheSameSurfacesAgree) {
  const std::vector<SourceConsistency> result = map_consistency(two_lidars(Eigen::Vector3f::Zero()), 2);
  ASSERT_EQ(result.size(), 2u);
  for (const SourceConsistency& c : result) {
    EXPECT_GT(c.self_planes, 300u);
    EXPECT_GT(c.cross_planes, 300u);
    EXPECT_NEAR(c.self_m, 0.0067, 0.003);  // median |N(0, 1 cm)| off a plane fitted to noisy points
    EXPECT_LT(consistency_ratio(result, &c - result.data()), 1.5) << int{c.source};
  }
}

TEST(MapConsistency, AMisplacedLidarsPointsLieOffTheOthersPlanes) {
  const std::vector<SourceConsistency> result = map_consistency(two_lidars(Eigen::Vector3f(0.1F, 0.1F, 0.1F)), 2);
  ASSERT_EQ(result.size(), 2u);
  for (const SourceConsistency& c : result) {
    EXPECT_NEAR(c.cross_m, 0.1, 0.03) << int{c.source};  // the offset along each surface's normal
    EXPECT_GT(consistency_ratio(result, &c - result.data()), 5.0) << int{c.source};
  }
}

TEST(MapConsistency, ASourceWithoutPointsIsLeftOutAndOneAloneHasNoCrossPlanes) {
  VoxelMap map(1.0, 60);
  const std::vector<Eigen::Vector3f> only = corner(3, Eigen::Vector3f::Zero());
  map.add(only, std::vector<std::uint8_t>(only.size(), 1));
  const std::vector<SourceConsistency> result = map_consistency(map, 3);
  ASSERT_EQ(result.size(), 1u);
  EXPECT_EQ(result[0].source, 1);
  EXPECT_GT(result[0].self_planes, 300u);
  EXPECT_EQ(result[0].cross_planes, 0u);
  EXPECT_EQ(consistency_ratio(result, 0), 0.0);
}

// A precise LiDAR (1 mm) beside a noisy one (3 cm) on the same surfaces: the precise one's points lie farther from
// the noisy planes than from its own, by the noise, not by a misplacement: judged against the largest own noise.
TEST(MapConsistency, APreciseLidarIsJudgedAgainstTheNoisierOnesPlanesNoise) {
  VoxelMap map(1.0, 60);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> along(0.2F, 6.0F);
  for (const auto& [source, sigma] : {std::pair<std::uint8_t, float>{0, 0.03F}, {1, 0.001F}}) {
    std::normal_distribution<float> noise(0.0F, sigma);
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < 400; ++i) points.emplace_back(along(rng), along(rng), noise(rng));  // ~12 per m^2, as a map holds
    map.add(points, std::vector<std::uint8_t>(points.size(), source));
  }
  const std::vector<SourceConsistency> result = map_consistency(map, 2);
  ASSERT_EQ(result.size(), 2u);
  EXPECT_GT(result[1].cross_m / result[1].self_m, 5.0);  // its own planes are 30x tighter
  EXPECT_LT(consistency_ratio(result, 1), 1.5);
}

}  // namespace
}  // namespace mlidar::slam
