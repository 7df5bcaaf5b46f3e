// solve_calibration_window without noise: features of a LiDAR seen from three
// known base poses against a map of three orthogonal planes recover the true
// T_base_lidar from a 1 deg / 3 cm start, with a full-rank information; with
// no features nothing is solved and the start is returned.
#include <array>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "mlidar/slam/calibration_window.hpp"

namespace mlidar::slam {
namespace {

/// World points on the floor z = 0, the wall x = 4 and the wall y = 4 (0.2 m grid).
std::vector<Eigen::Vector3f> box_points() {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const float a = 0.2F * static_cast<float>(i), b = 0.2F * static_cast<float>(j);
      points.emplace_back(a, b, 0.0F);
      points.emplace_back(4.0F, a, b);
      points.emplace_back(a, 4.0F, b);
    }
  return points;
}

TEST(CalibrationWindow, RecoversTheExtrinsicWithoutNoise) {
  VoxelMap planes(1.0, 60);
  VoxelMap edges(1.0, 10);
  const std::vector<Eigen::Vector3f> world = box_points();
  planes.add(world);
  const RegistrationConfig config;
  const MapView map{edges, planes, config};
  Vec6 truth_tangent;
  truth_tangent << 0.1, -0.4, -0.2, 0.7, 0.05, -0.1;
  const SE3 T_true = SE3::exp(truth_tangent);
  const std::array<Vec6, 3> pose_tangents = {(Vec6() << 1.0, 1.0, 1.5, 0, 0, 0).finished(),
                                             (Vec6() << 1.5, 1.2, 1.4, 0.05, 0, 0.3).finished(),
                                             (Vec6() << 2.0, 1.5, 1.6, 0, -0.05, 0.6).finished()};
  std::vector<CalibrationFrame> frames;
  for (const Vec6& tangent : pose_tangents) {
    CalibrationFrame frame;
    frame.T_world_base = SE3::exp(tangent);
    const SE3 T_lidar_world = (frame.T_world_base * T_true).inverse();
    // Every other world point at least 0.5 m from the box's edges (inside the plane patches), in the LiDAR frame.
    for (std::size_t i = 0; i < world.size(); i += 2) {
      const Vec3 p = world[i].cast<double>();
      if ((p.array() >= 0.5 && p.array() <= 3.5).count() != 2) continue;
      frame.features.planes.push_back((T_lidar_world * p).cast<float>());
    }
    frames.push_back(std::move(frame));
  }
  Vec6 error;
  error << 0.03, -0.02, 0.01, 0.01, -0.01, 0.012;
  const SE3 start = SE3::exp(error) * T_true;
  CalibrationWindowOptions options;
  options.gates_m = {0.5, 0.1};
  const CalibrationWindowResult result = solve_calibration_window(frames, start, map, options);
  ASSERT_TRUE(result.solved);
  EXPECT_LT((result.T_base_lidar.inverse() * T_true).log().norm(), 1e-4);
  EXPECT_LT(result.fit.mean_residual_m(), 1e-3);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat6>(result.information).eigenvalues()(0), 1.0);
  // Settled: the last pass at the last gate moved it less than the tolerances, within the pass budget.
  EXPECT_TRUE(result.settled);
  EXPECT_LE(result.last_step_m, options.settle_translation_m);
  EXPECT_LE(result.last_step_rad, options.settle_rotation_rad);
  EXPECT_GE(result.passes, 2);
  EXPECT_LE(result.passes, 2 + options.settle_passes);
  // Without extra passes exactly the two gates run; the start 3 cm off needs more than one to settle.
  CalibrationWindowOptions gates_only = options;
  gates_only.settle_passes = 0;
  EXPECT_EQ(solve_calibration_window(frames, start, map, gates_only).passes, 2);
  CalibrationWindowOptions one_gate = gates_only;
  one_gate.gates_m = {0.1};
  const CalibrationWindowResult one_pass = solve_calibration_window(frames, start, map, one_gate);
  EXPECT_EQ(one_pass.passes, 1);
  EXPECT_FALSE(one_pass.settled);

  std::vector<CalibrationFrame> empty(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) empty[i].T_world_base = frames[i].T_world_base;
  const CalibrationWindowResult none = solve_calibration_window(empty, start, map, options);
  EXPECT_FALSE(none.solved);
  EXPECT_LT((none.T_base_lidar.inverse() * start).log().norm(), 1e-12);
}

}  // namespace
}  // namespace mlidar::slam
