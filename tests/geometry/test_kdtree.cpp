// KdTree3f against brute force (STYLE.md habit 10): same neighbour sets and
// distances for knn and radius queries on seeded random clouds.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "mlidar/geometry/kdtree.hpp"

namespace mlidar {
namespace {

std::vector<Eigen::Vector3f> random_cloud(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coordinate(-5.0F, 5.0F);
  std::vector<Eigen::Vector3f> points(count);
  for (auto& point : points) point = {coordinate(rng), coordinate(rng), coordinate(rng)};
  return points;
}

std::vector<Neighbor> brute_force_all(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& query) {
  std::vector<Neighbor> all(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) all[i] = {static_cast<std::uint32_t>(i), (points[i] - query).squaredNorm()};
  std::sort(all.begin(), all.end(), [](const Neighbor& a, const Neighbor& b) {
    return a.distance_sq < b.distance_sq || (a.distance_sq == b.distance_sq && a.index < b.index);
  });
  return all;
}

TEST(KdTree3f, KnnMatchesBruteForce) {
  const auto points = random_cloud(2000, 7);
  const KdTree3f tree(points, 8);
  const auto queries = random_cloud(50, 8);
  for (const auto& query : queries) {
    for (const std::size_t k : {1UL, 5UL, 37UL}) {
      const auto found = tree.knn(query, k);
      const auto expected = brute_force_all(points, query);
      ASSERT_EQ(found.size(), k);
      for (std::size_t i = 0; i < k; ++i) {
        EXPECT_FLOAT_EQ(found[i].distance_sq, expected[i].distance_sq);
        EXPECT_FLOAT_EQ((points[found[i].index] - query).squaredNorm(), found[i].distance_sq);
      }
    }
  }
}

TEST(KdTree3f, RadiusMatchesBruteForce) {
  const auto points = random_cloud(3000, 11);
  const KdTree3f tree(points);
  const auto queries = random_cloud(40, 12);
  for (const auto& query : queries) {
    const float radius = 1.3F;
    const auto found = tree.radius_search(query, radius);
    std::vector<Neighbor> expected;
    for (const auto& neighbor : brute_force_all(points, query)) {
      if (neighbor.distance_sq <= radius * radius) expected.push_back(neighbor);
    }
    ASSERT_EQ(found.size(), expected.size());
    ASSERT_FALSE(found.empty());
    for (std::size_t i = 0; i < found.size(); ++i) {
      EXPECT_EQ(found[i].index, expected[i].index);
      EXPECT_FLOAT_EQ(found[i].distance_sq, expected[i].distance_sq);
    }
    std::vector<Neighbor> unsorted;
    tree.radius_search_unsorted(query, radius, unsorted);
    EXPECT_EQ(unsorted.size(), expected.size());
  }
}

TEST(KdTree3f, OwnsItsPointsAndHandlesEdgeCases) {
  auto points = random_cloud(10, 3);
  const Eigen::Vector3f first = points[0];
  KdTree3f tree(points);
  points.clear();  // the tree keeps its own copy
  ASSERT_EQ(tree.size(), 10U);
  EXPECT_EQ(tree.knn(first, 1).at(0).index, 0U);
  EXPECT_EQ(tree.knn(first, 50).size(), 10U);  // k larger than the cloud
  EXPECT_TRUE(tree.knn(first, 0).empty());
  EXPECT_EQ(tree.radius_search(first, 0.0F).size(), 1U);  // the point itself
  const KdTree3f moved = std::move(tree);
  EXPECT_EQ(moved.size(), 10U);

  const KdTree3f empty(std::vector<Eigen::Vector3f>{});
  EXPECT_TRUE(empty.knn(first, 3).empty());
  EXPECT_TRUE(empty.radius_search(first, 1.0F).empty());
}

TEST(KdTree3f, RejectsNonFinitePoints) {
  std::vector<Eigen::Vector3f> points = {{0, 0, 0}, {std::numeric_limits<float>::quiet_NaN(), 0, 0}};
  EXPECT_THROW(KdTree3f{points}, std::invalid_argument);
}

}  // namespace
}  // namespace mlidar
