// Sliding-window back end: residual Jacobians against central differences of
// the residuals written out directly; exact recovery of a noise-free two-frame
// window in calibration (eq 4.21) and odometry (eq 4.22) modes; the extrinsic
// information's null direction in a scene of vertical walls.
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "mlidar/slam/window_linearize.hpp"
#include "mlidar/slam/window_solver.hpp"
#include "slam/window_scene.hpp"

namespace mlidar::slam {
namespace {

using test::distance;
using test::perturb;

/// Jacobian stacked from the rows: J = sum n_k grad_k^T (3 x 12, [pose, extrinsic]).
Eigen::Matrix<double, 3, 12> stacked_jacobian(const ResidualRows& rows) {
  Eigen::Matrix<double, 3, 12> J = Eigen::Matrix<double, 3, 12>::Zero();
  for (std::size_t k = 0; k < static_cast<std::size_t>(rows.count); ++k) J += rows.directions[k] * rows.gradients[k].transpose();
  return J;
}

/// Central differences of f(T_world_base, T_base_lidar) under left perturbations of each.
template <typename F>
Eigen::Matrix<double, 3, 12> numeric_jacobian(const F& f, const SE3& pose, const SE3& extrinsic) {
  const double h = 1e-6;
  Eigen::Matrix<double, 3, 12> J;
  for (int k = 0; k < 6; ++k) {
    Vec6 d = Vec6::Zero();
    d(k) = h;
    J.col(k) = (f(SE3::exp(d) * pose, extrinsic) - f(SE3::exp(-d) * pose, extrinsic)) / (2.0 * h);
    J.col(6 + k) = (f(pose, SE3::exp(d) * extrinsic) - f(pose, SE3::exp(-d) * extrinsic)) / (2.0 * h);
  }
  return J;
}

TEST(WindowResiduals, PlaneAndEdgeJacobiansMatchNumeric) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto random_vec = [&] { return Vec3(n(rng), n(rng), n(rng)); };
  for (int trial = 0; trial < 20; ++trial) {
    const SE3 pose(so3_exp(random_vec()), random_vec() * 10.0);
    const SE3 extrinsic(so3_exp(random_vec()), random_vec());
    const Vec3 x = random_vec() * 8.0;
    const PlaneCorrespondence plane{0, 0, x, {random_vec().normalized(), n(rng) * 5.0}};
    const EdgeCorrespondence edge{0, 0, x, random_vec() * 3.0, random_vec().normalized()};
    // Eq 4.7: r = n (n^T q + d); eq 4.8 (summed): r = (I - u u^T)(q - a).
    const auto plane_r = [&](const SE3& T, const SE3& E) -> Vec3 {
      const Vec3 q = T * (E * x);
      return plane.plane_world.normal * (plane.plane_world.normal.dot(q) + plane.plane_world.offset);
    };
    const auto edge_r = [&](const SE3& T, const SE3& E) -> Vec3 {
      const Vec3 d = T * (E * x) - edge.line_point_world;
      return d - edge.line_direction_world.dot(d) * edge.line_direction_world;
    };
    const ResidualRows p = plane_rows(plane, pose, extrinsic);
    const ResidualRows e = edge_rows(edge, pose, extrinsic);
    EXPECT_LT((p.residual() - plane_r(pose, extrinsic)).norm(), 1e-9);
    EXPECT_LT((e.residual() - edge_r(pose, extrinsic)).norm(), 1e-9);
    EXPECT_NEAR(e.squared_norm(), edge_r(pose, extrinsic).squaredNorm(), 1e-8);
    const auto Jp = stacked_jacobian(p);
    const auto Je = stacked_jacobian(e);
    EXPECT_LT((numeric_jacobian(plane_r, pose, extrinsic) - Jp).norm(), 1e-5 * (1.0 + Jp.norm())) << trial;
    EXPECT_LT((numeric_jacobian(edge_r, pose, extrinsic) - Je).norm(), 1e-5 * (1.0 + Je.norm())) << trial;
  }
}

/// Two poses (the first fixed), two LiDARs, the room scene.
struct TwoFrameWindow {
  WindowState truth;
  WindowProblem problem;
};

TwoFrameWindow two_frame_window(const test::WindowScene& scene, const std::vector<SE3>& poses, int per_lidar, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const SE3 base_lidar(so3_exp(Vec3(0.0, 0.0, 0.3)), Vec3(0.2, 0.0, 0.4));
  const SE3 aux_lidar(so3_exp(Vec3(0.1, -0.6, 1.2)), Vec3(-0.5, 0.8, 0.1));
  TwoFrameWindow window;
  window.truth = WindowState::make(poses, {base_lidar, aux_lidar}, 1, true);
  window.problem = test::observe(scene, window.truth, per_lidar, rng);
  return window;
}

const std::vector<SE3> kTwoPoses{SE3(so3_exp(Vec3(0.02, -0.01, 0.3)), Vec3(1.0, -0.5, 0.2)),
                                 SE3(so3_exp(Vec3(-0.05, 0.04, 0.7)), Vec3(2.1, 0.4, 0.3))};

TEST(WindowSolver, CalibrationModeRecoversPerturbedExtrinsicExactly) {
  std::mt19937_64 rng(21);
  const TwoFrameWindow window = two_frame_window(test::room_scene(6, rng), kTwoPoses, 300, 22);
  WindowState initial = window.truth;
  initial.T_base_lidar[1] = perturb(initial.T_base_lidar[1], 0.05, 3.0 * M_PI / 180.0, rng);
  initial.T_world_base[1] = perturb(initial.T_world_base[1], 0.08, 2.0 * M_PI / 180.0, rng);
  const WindowSolution solution = solve_window(window.problem, initial);
  EXPECT_TRUE(solution.converged);
  EXPECT_LT(distance(solution.state.T_base_lidar[1], window.truth.T_base_lidar[1]), 1e-6);
  EXPECT_LT(distance(solution.state.T_world_base[1], window.truth.T_world_base[1]), 1e-6);
  EXPECT_LT(distance(solution.state.T_world_base[0], window.truth.T_world_base[0]), 1e-15);  // held fixed
  EXPECT_LT(distance(solution.state.T_base_lidar[0], window.truth.T_base_lidar[0]), 1e-15);
  EXPECT_GT(solution.initial_cost, 1e-3);
  EXPECT_LT(solution.final_cost, 1e-14);
  EXPECT_GE(solution.iterations, 2);
  // Observable scene: the auxiliary extrinsic's information is well conditioned, the base's is zero (fixed).
  const Vec6 values = Eigen::SelfAdjointEigenSolver<Mat6>(solution.extrinsic_information[1]).eigenvalues();
  EXPECT_GT(values(0), 1e-2 * values(5));
  EXPECT_EQ(solution.extrinsic_information[0], Mat6::Zero());
  EXPECT_TRUE(solution.covariance_valid);
  EXPECT_EQ(solution.pose_covariance[0], Mat6::Zero());
  EXPECT_GT(solution.pose_covariance[1].diagonal().minCoeff(), 0.0);
}

TEST(WindowSolver, OdometryModeRecoversMotionExactly) {
  std::mt19937_64 rng(31);
  TwoFrameWindow window = two_frame_window(test::room_scene(6, rng), kTwoPoses, 300, 32);
  set_extrinsic_mode(window.truth, ExtrinsicMode::kFixed);
  WindowState initial = window.truth;
  initial.T_world_base[1] = perturb(initial.T_world_base[1], 0.15, 4.0 * M_PI / 180.0, rng);
  const WindowSolution solution = solve_window(window.problem, initial);
  EXPECT_TRUE(solution.converged);
  EXPECT_LT(distance(solution.state.T_world_base[1], window.truth.T_world_base[1]), 1e-6);
  EXPECT_LT(distance(solution.state.T_base_lidar[1], window.truth.T_base_lidar[1]), 1e-15);
  EXPECT_EQ(solution.extrinsic_information[1], Mat6::Zero());  // not a variable in this mode
}

TEST(WindowSolver, SchurInformationIsBelowTheBlockWhenTheExtrinsicSharesAVariablePose) {
  std::mt19937_64 rng(41);
  const TwoFrameWindow window = two_frame_window(test::room_scene(6, rng), kTwoPoses, 200, 42);
  const WindowSolution solution = solve_window(window.problem, window.truth);
  const VariableLayout layout(window.truth);
  const WindowLinearSystem system = linearize_window(window.problem, window.truth, layout, 0.1);
  const Mat6 block = system.H.block<6, 6>(layout.extrinsic_offset[1], layout.extrinsic_offset[1]);
  // Pose 1's residuals from the auxiliary LiDAR tie it to the extrinsic: the marginal information is strictly smaller.
  const Vec6 gap = Eigen::SelfAdjointEigenSolver<Mat6>(block - solution.extrinsic_information[1]).eigenvalues();
  EXPECT_GT(gap(0), -1e-9 * block.norm());
  EXPECT_GT(gap(5), 1e-3 * block.norm());
  // Equal to the inverse of the extrinsic's marginal covariance (no prior here).
  const Eigen::MatrixXd covariance = system.H.inverse();
  const Mat6 marginal = covariance.block<6, 6>(layout.extrinsic_offset[1], layout.extrinsic_offset[1]).inverse();
  EXPECT_LT((marginal - solution.extrinsic_information[1]).norm(), 1e-8 * marginal.norm());
}

TEST(WindowSolver, VerticalWallsLeaveTheExtrinsicZShiftUnobservable) {
  // Planar (yaw-only) motion among walls whose normals are all horizontal: a shift of the
  // auxiliary LiDAR along the base z axis changes no residual.
  const std::vector<SE3> planar{SE3(so3_exp(Vec3(0.0, 0.0, 0.2)), Vec3(0.5, 0.0, 0.0)),
                                SE3(so3_exp(Vec3(0.0, 0.0, 0.6)), Vec3(1.5, 0.7, 0.0))};
  const TwoFrameWindow window = two_frame_window(test::corridor_scene(), planar, 300, 52);
  std::mt19937_64 rng(53);
  WindowState initial = window.truth;
  initial.T_base_lidar[1] = perturb(initial.T_base_lidar[1], 0.0, 1.0 * M_PI / 180.0, rng);
  const WindowSolution solution = solve_window(window.problem, initial);
  const Eigen::SelfAdjointEigenSolver<Mat6> eigen(solution.extrinsic_information[1]);
  EXPECT_LT(eigen.eigenvalues()(0), 1e-9 * eigen.eigenvalues()(5));
  EXPECT_GT(eigen.eigenvalues()(1), 1e-3 * eigen.eigenvalues()(5));  // only one direction is lost
  EXPECT_GT(std::abs(eigen.eigenvectors().col(0)(2)), 1.0 - 1e-9);   // translation along z
  EXPECT_FALSE(solution.covariance_valid);                           // pose 1's z is unobservable too
  EXPECT_LT(solution.final_cost, 1e-14);
}

TEST(WindowSolver, RejectsInconsistentProblems) {
  WindowState state = WindowState::make({SE3()}, {SE3(), SE3()}, 1, true);
  WindowProblem problem;
  problem.planes.push_back({1, 0, Vec3::Zero(), {}});  // frame 1 is outside a one-pose window
  EXPECT_THROW(solve_window(problem, state), std::invalid_argument);
  problem.planes.clear();
  state.extrinsic_fixed[0] = false;
  EXPECT_THROW(solve_window(problem, state), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::slam
