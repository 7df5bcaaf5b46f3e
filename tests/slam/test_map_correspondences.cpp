// map_matcher / map_correspondences against analytic geometry: map points on
// a known plane or line give back that plane or line; a point offset from it
// by a known distance gives that residual; a window problem built from them
// has the documented frame, LiDAR and world geometry; a feature beyond the gate is dropped.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/slam/map_correspondences.hpp"
#include "mlidar/slam/map_matcher.hpp"

namespace mlidar::slam {
namespace {

/// A 0.1 m grid on the plane z = 0.3 over [-2, 2]^2.
VoxelMap plane_map() {
  VoxelMap map(1.0, 50);
  std::vector<Eigen::Vector3f> points;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) points.emplace_back(0.1F * static_cast<float>(i), 0.1F * static_cast<float>(j), 0.3F);
  map.add(points);
  return map;
}

/// Points every 0.05 m on the line through (1, 1, 0) along y.
VoxelMap line_map() {
  VoxelMap map(1.0, 50);
  std::vector<Eigen::Vector3f> points;
  for (int i = -40; i <= 40; ++i) points.emplace_back(1.0F, 1.0F + 0.05F * static_cast<float>(i), 0.0F);
  map.add(points);
  return map;
}

TEST(MapMatcher, PlaneOfGridNeighboursIsTheGridPlane) {
  const VoxelMap map = plane_map();
  const RegistrationConfig config;
  const auto plane = match_plane(map, Vec3(0.23, -0.41, 0.35), 1.0F, config);
  ASSERT_TRUE(plane.has_value());
  EXPECT_NEAR(std::abs(plane->normal.z()), 1.0, 1e-9);
  // n^T q + d at a point 0.05 m above the plane.
  EXPECT_NEAR(std::abs(plane->normal.dot(Vec3(0.23, -0.41, 0.35)) + plane->offset), 0.05, 1e-6);
  // Beyond the search radius there is nothing to fit.
  EXPECT_FALSE(match_plane(map, Vec3(0.0, 0.0, 2.0), 1.0F, config).has_value());
}

TEST(MapMatcher, APlaneTakesItsExtraNeighboursOnlyWithinTheExtraRadius) {
  // Five points on z = 0 nearest the query (0, 0, 0.05) (0.05 and 0.112 m away), three more at z = 0.1 on a
  // 0.3 m circle at 120 deg (0.304 m away). By symmetry the eight points' normal is z and their mean height
  // 3 x 0.1 / 8 = 0.0375 m, so the query is 0.05 m off the five's plane and 0.0125 m off the eight's.
  VoxelMap map(1.0, 50);
  const float s = 0.15F * std::sqrt(3.0F);
  const std::vector<Eigen::Vector3f> points{{0.0F, 0.0F, 0.0F},  {0.1F, 0.0F, 0.0F}, {-0.1F, 0.0F, 0.0F}, {0.0F, 0.1F, 0.0F},
                                            {0.0F, -0.1F, 0.0F}, {0.3F, 0.0F, 0.1F}, {-0.15F, s, 0.1F},   {-0.15F, -s, 0.1F}};
  map.add(points);
  const Vec3 q(0.0, 0.0, 0.05);
  const auto residual = [&](int neighbors_max, double extra_radius_m) {
    RegistrationConfig config;
    config.plane_neighbors_max = neighbors_max;
    config.plane_extra_radius_m = extra_radius_m;
    const auto plane = match_plane(map, q, 1.0F, config);
    EXPECT_TRUE(plane.has_value());
    EXPECT_NEAR(std::abs(plane->normal.z()), 1.0, 1e-6);
    return std::abs(plane->normal.dot(q) + plane->offset);
  };
  EXPECT_NEAR(residual(5, 0.5), 0.05, 1e-6);    // the default: five neighbours
  EXPECT_NEAR(residual(8, 0.5), 0.0125, 1e-6);  // all eight within 0.5 m
  EXPECT_NEAR(residual(8, 0.3), 0.05, 1e-6);    // the three extra are 0.304 m away: left out
}

TEST(MapMatcher, APatchOfOneScanLineNarrowerThanTheRangeNoiseIsNoPlane) {
  // A 16-beam LiDAR 1.3 m above the ground: the -15 deg beam every 0.1 deg of azimuth, each range 5 cm long or
  // short in turn (range noise lies along the beams). The five points nearest the ground point below the middle
  // beam span 1.2 cm across the beams and 10 cm along them: they lie on the sheet the beams sweep, and pass the
  // colinearity and tolerance checks with a normal 15 deg off the ground's.
  const double elevation = -15.0 * std::numbers::pi / 180.0;
  const double ground_range = 1.3 / std::sin(-elevation);
  std::vector<Eigen::Vector3f> points;
  for (int i = -10; i <= 10; ++i) {
    const double azimuth = 0.1 * i * std::numbers::pi / 180.0;
    const Vec3 beam(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    points.push_back(((ground_range + (i % 2 == 0 ? -0.05 : 0.05)) * beam).cast<float>());
  }
  VoxelMap map(1.0, 50);
  map.add(points);
  const Vec3 q = ground_range * Vec3(std::cos(elevation), 0.0, std::sin(elevation));
  RegistrationConfig config;
  const auto sheet = match_plane(map, q, 1.0F, config);
  ASSERT_TRUE(sheet.has_value());
  EXPECT_GT(std::acos(std::abs(sheet->normal.z())) * 180.0 / std::numbers::pi, 14.0);
  config.plane_min_extent_m = 0.025;  // half the 5 cm range sigma
  EXPECT_FALSE(match_plane(map, q, 1.0F, config).has_value());
  // A patch wider than the noise still is: the 0.1 m grid's five nearest spread 6 cm.
  const auto grid = match_plane(plane_map(), Vec3(0.23, -0.41, 0.35), 1.0F, config);
  ASSERT_TRUE(grid.has_value());
  EXPECT_NEAR(std::abs(grid->normal.z()), 1.0, 1e-9);
}

TEST(MapMatcher, LineOfColinearNeighboursIsTheLine) {
  const VoxelMap map = line_map();
  const RegistrationConfig config;
  const auto line = match_line(map, Vec3(1.02, 1.3, 0.01), 1.0F, config);
  ASSERT_TRUE(line.has_value());
  EXPECT_NEAR(std::abs(line->direction.y()), 1.0, 1e-9);
  EXPECT_NEAR(line->point.x(), 1.0, 1e-6);
  EXPECT_NEAR(line->point.z(), 0.0, 1e-6);
  // Planar neighbours are no line.
  EXPECT_FALSE(match_line(plane_map(), Vec3(0.0, 0.0, 0.3), 1.0F, config).has_value());
}

TEST(MapCorrespondences, WindowTermsAndFitFollowThePose) {
  const VoxelMap planes = plane_map();
  const VoxelMap edges = line_map();
  const RegistrationConfig config;
  const MapView map{edges, planes, config};
  // LiDAR-frame features; the pose moves them up by 0.3 m and the plane feature ends 0.04 m above the plane.
  LidarFrameFeatures features;
  features.planes = {Eigen::Vector3f(0.2F, 0.1F, 0.04F), Eigen::Vector3f(0.2F, 0.1F, 3.0F)};  // the second: far beyond the gate
  features.edges = {Eigen::Vector3f(1.03F, 1.2F, -0.3F)};
  const SE3 T_world_lidar(Quat::Identity(), Vec3(0.0, 0.0, 0.3));
  WindowProblem problem;
  const MapFit fit = add_map_correspondences(features, 2, 1, T_world_lidar, map, 0.5, problem);
  ASSERT_EQ(problem.planes.size(), 1U);
  ASSERT_EQ(problem.edges.size(), 1U);
  EXPECT_EQ(problem.planes[0].frame, 2);
  EXPECT_EQ(problem.planes[0].lidar, 1);
  EXPECT_NEAR((problem.planes[0].point_lidar - Vec3(0.2, 0.1, 0.04)).norm(), 0.0, 1e-6);
  EXPECT_NEAR(std::abs(problem.edges[0].line_direction_world.y()), 1.0, 1e-9);
  EXPECT_NEAR(fit.mean_residual_m(), (0.04 + 0.03) / 2.0, 1e-6);
  EXPECT_EQ(fit.planes, 1U);
  EXPECT_EQ(fit.edges, 1U);
  WindowProblem empty_problem;
  EXPECT_TRUE(std::isnan(add_map_correspondences(LidarFrameFeatures{}, 0, 0, T_world_lidar, map, 0.5, empty_problem).mean_residual_m()));
}

}  // namespace
}  // namespace mlidar::slam
