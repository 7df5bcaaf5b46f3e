// The sliding window over the trusted poses (eq 4.22, map in the pivot frame) on simulated frames with
// known poses: features sampled on a room's planes and lines (2 cm noise), a
// local map from the first frames at their true poses, and "odometry" poses
// that are the truth with independent errors of a few centimetres and tenths
// of a degree. Oracle: the true poses.
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/slam/odometry_window.hpp"
#include "slam/window_scene.hpp"

namespace mlidar::slam {
namespace {

SE3 true_pose(int k) {
  return SE3(so3_exp(Vec3(0.01 * std::sin(0.3 * k), 0.005 * k, 0.03 * k)), Vec3(0.15 * k, 0.4 * std::sin(0.1 * k), 0.02 * k));
}

/// `count` points of frame `k` in the base frame: 3 in 4 on the scene's planes, the rest on its lines.
LidarFrameFeatures sample_features(const test::WindowScene& scene, const SE3& T_world_base, int count, double noise_m,
                                   std::mt19937_64& rng) {
  const WindowState truth = WindowState::make({T_world_base}, {SE3::identity()}, 1, false);
  const WindowProblem observed = test::observe(scene, truth, count, rng);
  std::normal_distribution<double> noise(0.0, noise_m);
  const auto noisy = [&](const Vec3& p) -> Eigen::Vector3f {
    Vec3 q = p;
    for (int a = 0; a < 3; ++a) q(a) += noise(rng);
    return q.cast<float>();
  };
  LidarFrameFeatures features;
  for (const auto& c : observed.planes) features.planes.push_back(noisy(c.point_lidar));
  for (const auto& c : observed.edges) features.edges.push_back(noisy(c.point_lidar));
  return features;
}

/// World points of the first frames at their true poses.
void add_world(const LidarFrameFeatures& f, const SE3& T_world_base, VoxelMap& edges, VoxelMap& planes) {
  std::vector<Eigen::Vector3f> world(f.edges.size());
  transform_points(T_world_base, f.edges, world);
  edges.add(world);
  world.resize(f.planes.size());
  transform_points(T_world_base, f.planes, world);
  planes.add(world);
}

struct WindowRun {
  std::map<std::size_t, SE3> settled;  ///< reported once per frame
  std::vector<int> prior_ranks;
  std::vector<std::size_t> unsettled_counts;
  std::vector<SE3> odometry;
};

WindowRun run_window(int frames, double odometry_error_m, double odometry_error_rad, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const test::WindowScene scene = test::room_scene(8, rng);
  OdometryWindowConfig config;
  VoxelMap edges(config.edge_voxel_m, config.edge_points_per_voxel), planes(config.plane_voxel_m, config.plane_points_per_voxel);
  for (int k = -3; k < 0; ++k) add_world(sample_features(scene, true_pose(k), 4000, 0.02, rng), true_pose(k), edges, planes);
  OdometryWindow window(config, std::move(edges), std::move(planes));
  WindowRun run;
  for (int k = 0; k < frames; ++k) {
    // The odometry's pose: the truth with an independent error (the first p frames exact: they fix the gauge).
    const SE3 odometry = k < config.pivot ? true_pose(k) : test::perturb(true_pose(k), odometry_error_m, odometry_error_rad, rng);
    run.odometry.push_back(odometry);
    const OdometryWindowUpdate update =
        window.add(static_cast<std::size_t>(k), sample_features(scene, true_pose(k), 1500, 0.02, rng), odometry, SE3::identity());
    EXPECT_EQ(update.latest.frame, static_cast<std::size_t>(k));
    if (update.settled) {
      EXPECT_TRUE(run.settled.emplace(update.settled->frame, update.settled->T_world_base).second) << k;
    }
    run.prior_ranks.push_back(update.prior_rank);
    run.unsettled_counts.push_back(window.unsettled().size());
  }
  for (const WindowPose& pose : window.unsettled()) EXPECT_TRUE(run.settled.emplace(pose.frame, pose.T_world_base).second);
  return run;
}

TEST(OdometryWindow, RecoversKnownPosesBetterThanTheOdometryItStartsFrom) {
  const int frames = 14;
  const WindowRun run = run_window(frames, 0.05, 0.005, 3);
  ASSERT_EQ(run.settled.size(), static_cast<std::size_t>(frames));  // every frame once
  double odometry_sum = 0.0, window_sum = 0.0;
  for (int k = 2; k < frames; ++k) {
    const auto index = static_cast<std::size_t>(k);
    odometry_sum += test::distance(run.odometry[index], true_pose(k));
    window_sum += test::distance(run.settled.at(index), true_pose(k));
    EXPECT_LT((run.settled.at(index).translation() - true_pose(k).translation()).norm(), 0.01) << k;
  }
  EXPECT_LT(window_sum, 0.25 * odometry_sum);
}

TEST(OdometryWindow, ExactOdometryStaysExact) {
  const WindowRun run = run_window(10, 0.0, 0.0, 5);
  for (const auto& [frame, pose] : run.settled) EXPECT_LT(test::distance(pose, true_pose(static_cast<int>(frame))), 0.01) << frame;
}

TEST(OdometryWindow, ShiftsKeepTheWindowShapeAndCarryTheRelativePrior) {
  // Eq 4.22 with the map attached to the pivot: marginalizing the pivot leaves a prior on the relative
  // poses of the N + 1 - p frames after it, rank 6 (N - p) (their common motion is unobserved); none
  // before the window first fills.
  const OdometryWindowConfig config;
  const WindowRun run = run_window(12, 0.03, 0.003, 7);
  const auto variable = static_cast<std::size_t>(config.size + 1 - config.pivot);
  for (std::size_t k = 0; k < run.prior_ranks.size(); ++k) {
    EXPECT_EQ(run.prior_ranks[k], k < static_cast<std::size_t>(config.size + 1) ? 0 : 6 * (config.size - config.pivot)) << k;
    const std::size_t expected = k + 1 <= static_cast<std::size_t>(config.pivot) ? 0 : std::min(variable, k + 1 - config.pivot);
    EXPECT_EQ(run.unsettled_counts[k], expected) << k;
  }
}

TEST(OdometryWindow, RejectsAPivotOutsideTheWindow) {
  OdometryWindowConfig config;
  config.pivot = config.size + 1;
  EXPECT_THROW(OdometryWindow(config, VoxelMap(1.0, 10), VoxelMap(1.0, 20)), std::invalid_argument);
  config.pivot = 0;
  EXPECT_THROW(OdometryWindow(config, VoxelMap(1.0, 10), VoxelMap(1.0, 20)), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::slam
