// The Ceres formulation of the window problem (slam/ceres_window) against the
// hand-written solver on the same noisy windows: both reach the same solution
// and the same cost, in calibration (eq 4.21) and odometry (eq 4.22) modes. The
// solver comparison in docs/benchmarks.md rests on this agreement.
#include <random>

#include <gtest/gtest.h>

#include "mlidar/slam/ceres_window.hpp"
#include "mlidar/slam/window_linearize.hpp"
#include "mlidar/slam/window_solver.hpp"
#include "slam/window_scene.hpp"

namespace mlidar::slam {
namespace {

struct NoisyWindow {
  WindowProblem problem;
  WindowState initial;
};

/// 5 poses (the first 2 fixed), a base and an auxiliary LiDAR, 2 cm feature noise, variables perturbed 5 cm / 2 deg.
NoisyWindow noisy_window(bool calibrate, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const test::WindowScene scene = test::room_scene(20, rng);
  std::vector<SE3> poses;
  for (int k = 0; k < 5; ++k) poses.emplace_back(so3_exp(Vec3(0.0, 0.01 * k, 0.1 * k)), Vec3(0.5 * k, 0.05 * k, 0.0));
  const std::vector<SE3> extrinsics{SE3(), SE3(so3_exp(Vec3(0.2, -0.1, 1.6)), Vec3(0.4, -0.3, 0.1))};
  NoisyWindow window;
  window.initial = WindowState::make(poses, extrinsics, 2, calibrate);
  window.problem = test::observe(scene, window.initial, 300, rng);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (auto& c : window.problem.planes) c.point_lidar += Vec3(noise(rng), noise(rng), noise(rng));
  for (auto& c : window.problem.edges) c.point_lidar += Vec3(noise(rng), noise(rng), noise(rng));
  for (std::size_t i = 2; i < poses.size(); ++i) window.initial.T_world_base[i] = test::perturb(poses[i], 0.05, 0.035, rng);
  if (calibrate) window.initial.T_base_lidar[1] = test::perturb(extrinsics[1], 0.05, 0.035, rng);
  return window;
}

double distance(const SE3& a, const SE3& b) { return (a.inverse() * b).log().norm(); }

void expect_same_solution(bool calibrate, std::uint64_t seed) {
  const NoisyWindow window = noisy_window(calibrate, seed);
  WindowSolverConfig config;
  config.max_iterations = 30;
  const WindowSolution ours = solve_window(window.problem, window.initial, config);
  CeresWindowOptions ceres_options;
  ceres_options.max_iterations = 30;
  const CeresWindowResult ceres = solve_window_ceres(window.problem, window.initial, ceres_options);
  ASSERT_TRUE(ours.converged);
  // Both minimize the same cost from the same start (Ceres reports it as window_cost does).
  EXPECT_NEAR(ceres.initial_cost, window_cost(window.problem, window.initial, 0.1), 1e-9 * ceres.initial_cost);
  EXPECT_LT(ceres.final_cost, 0.1 * ceres.initial_cost);  // the 5 cm / 2 deg start costs ~30x the 2 cm noise
  EXPECT_NEAR(ceres.final_cost, ours.final_cost, 1e-6 * ours.final_cost);
  for (std::size_t i = 0; i < window.initial.T_world_base.size(); ++i)
    EXPECT_LT(distance(ceres.state.T_world_base[i], ours.state.T_world_base[i]), 1e-5) << "pose " << i;
  EXPECT_LT(distance(ceres.state.T_base_lidar[1], ours.state.T_base_lidar[1]), 1e-5);
  EXPECT_LT(distance(ceres.state.T_world_base[0], window.initial.T_world_base[0]), 1e-12);  // fixed stays fixed
}

TEST(CeresWindow, AgreesWithTheHandWrittenSolverInCalibrationMode) { expect_same_solution(true, 21); }
TEST(CeresWindow, AgreesWithTheHandWrittenSolverInOdometryMode) { expect_same_solution(false, 22); }

TEST(CeresWindow, RejectsAProblemWithAPrior) {
  NoisyWindow window = noisy_window(true, 23);
  window.problem.prior.variables.push_back({VariableId::Kind::kPose, 2});
  window.problem.prior.linearization_points.push_back(window.initial.T_world_base[2]);
  window.problem.prior.jacobian = Eigen::MatrixXd::Identity(6, 6);
  window.problem.prior.residual = Eigen::VectorXd::Zero(6);
  EXPECT_THROW(solve_window_ceres(window.problem, window.initial), std::invalid_argument);
}

TEST(CeresWindow, RejectsAMapAnchoredAtAPose) {
  NoisyWindow window = noisy_window(true, 29);
  window.problem.anchor = {0, window.initial.T_world_base[0]};
  EXPECT_THROW(solve_window_ceres(window.problem, window.initial), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::slam
