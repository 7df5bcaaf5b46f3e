// The window's map attached to the pivot (thesis eq 4.21-4.22: residuals
// r(x_p^-1 x_k, p)) against an independent evaluation in the pivot's frame:
// the normal equations against a numeric Jacobian over every variable block
// (the pivot included), the marginalization of the pivot against the Schur
// complement of the full problem, the gauge it leaves, and the pivot's own
// features (T_p^-1 T_p cancels, so eq 4.21's extrinsic terms touch no pose).
#include <random>

#include <gtest/gtest.h>

#include "mlidar/slam/marginalization.hpp"
#include "mlidar/slam/window_linearize.hpp"
#include "mlidar/slam/window_solver.hpp"
#include "slam/window_scene.hpp"

namespace mlidar::slam {
namespace {

using test::kHuberOff;

struct AnchoredWindow {
  WindowState state;
  WindowProblem problem;
};

/// Poses 0 (the pivot), 1, 2 and an auxiliary LiDAR; features of frames 1 and 2 on a room's planes and
/// lines; the map found with the pivot at a reference estimate that differs from its current one.
AnchoredWindow anchored_window(std::uint64_t seed, bool calibrate) {
  std::mt19937_64 rng(seed);
  const std::vector<SE3> poses{SE3(so3_exp(Vec3(0.0, 0.0, 0.1)), Vec3(0.0, 0.0, 0.0)),
                               SE3(so3_exp(Vec3(0.02, 0.0, 0.3)), Vec3(1.0, 0.2, 0.0)),
                               SE3(so3_exp(Vec3(0.0, -0.03, 0.5)), Vec3(2.0, 0.5, 0.1))};
  const std::vector<SE3> extrinsics{SE3(), SE3(so3_exp(Vec3(0.2, 0.1, 1.5)), Vec3(0.3, -0.4, 0.2))};
  const WindowState truth = WindowState::make(poses, extrinsics, 0, calibrate);
  AnchoredWindow window;
  window.problem = test::observe(test::room_scene(3, rng), truth, 12, rng);
  std::erase_if(window.problem.planes, [](const PlaneCorrespondence& c) { return c.frame == 0; });
  std::erase_if(window.problem.edges, [](const EdgeCorrespondence& c) { return c.frame == 0; });
  window.problem.anchor = {0, test::perturb(poses[0], 0.02, 0.01, rng)};
  window.state = truth;
  for (SE3& T : window.state.T_world_base) T = test::perturb(T, 0.03, 0.01, rng);
  if (calibrate) window.state.T_base_lidar[1] = test::perturb(window.state.T_base_lidar[1], 0.02, 0.01, rng);
  return window;
}

/// The scalar rows in the pivot's frame, written out independently of window_linearize:
/// q_p = T_p^-1 T_k T_base_lidar x against the plane / line taken into the pivot's frame at its reference.
Eigen::VectorXd pivot_frame_rows(const WindowProblem& problem, const WindowState& state) {
  const SE3& T_ref = problem.anchor.T_world_base_reference;
  const SE3 T_pivot_world = state.T_world_base[static_cast<std::size_t>(problem.anchor.frame)].inverse();
  std::vector<double> rows;
  const auto q_pivot = [&](int frame, int lidar, const Vec3& x) {
    return T_pivot_world *
           (state.T_world_base[static_cast<std::size_t>(frame)] * (state.T_base_lidar[static_cast<std::size_t>(lidar)] * x));
  };
  for (const PlaneCorrespondence& c : problem.planes) {
    const Vec3 n = T_ref.rotation_matrix().transpose() * c.plane_world.normal;
    const double d = c.plane_world.offset + c.plane_world.normal.dot(T_ref.translation());
    rows.push_back(n.dot(q_pivot(c.frame, c.lidar, c.point_lidar)) + d);
  }
  for (const EdgeCorrespondence& c : problem.edges) {
    const Vec3 u = T_ref.rotation_matrix().transpose() * c.line_direction_world;
    const Vec3 a = T_ref.inverse() * c.line_point_world;
    const Vec3 n1 = u.unitOrthogonal();
    const Vec3 n2 = u.cross(n1);
    const Vec3 offset = q_pivot(c.frame, c.lidar, c.point_lidar) - a;
    rows.push_back(n1.dot(offset));
    rows.push_back(n2.dot(offset));
  }
  return Eigen::Map<const Eigen::VectorXd>(rows.data(), static_cast<Eigen::Index>(rows.size()));
}

/// Central differences of pivot_frame_rows over the layout's blocks (left perturbations).
Eigen::MatrixXd numeric_jacobian(const WindowProblem& problem, const WindowState& state, const VariableLayout& layout) {
  const double h = 1e-6;
  Eigen::MatrixXd J(pivot_frame_rows(problem, state).size(), layout.size);
  const auto perturbed = [&](int column, double step) {
    WindowState moved = state;
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(layout.size);
    dx(column) = step;
    retract(moved, layout, dx);
    return pivot_frame_rows(problem, moved);
  };
  for (int column = 0; column < layout.size; ++column) J.col(column) = (perturbed(column, h) - perturbed(column, -h)) / (2.0 * h);
  return J;
}

TEST(AnchoredWindow, NormalEquationsMatchANumericJacobianInThePivotFrame) {
  for (const bool calibrate : {false, true}) {
    const AnchoredWindow w = anchored_window(11, calibrate);
    const VariableLayout layout(w.state);  // the pivot is a variable here
    const Eigen::MatrixXd J = numeric_jacobian(w.problem, w.state, layout);
    const Eigen::VectorXd r = pivot_frame_rows(w.problem, w.state);
    const WindowLinearSystem system = linearize_window(w.problem, w.state, layout, kHuberOff);
    const Eigen::MatrixXd H = J.transpose() * J;
    EXPECT_LT((system.H - H).norm(), 1e-6 * H.norm()) << calibrate;
    EXPECT_LT((system.g - J.transpose() * r).norm(), 1e-6 * (J.transpose() * r).norm()) << calibrate;
    EXPECT_NEAR(system.cost, 0.5 * r.squaredNorm(), 1e-12 * r.squaredNorm()) << calibrate;
    EXPECT_GT(r.norm(), 1e-3);  // the state is off the truth and the pivot off its reference
  }
}

TEST(AnchoredWindow, MarginalizingThePivotEqualsTheSchurComplementOfTheFullProblem) {
  AnchoredWindow w = anchored_window(21, true);
  // An earlier prior on the pivot and pose 1 (a window shifted before).
  std::mt19937_64 rng(22);
  std::normal_distribution<double> normal(0.0, 1.0);
  LinearPrior& old = w.problem.prior;
  old.variables = {{VariableId::Kind::kPose, 0}, {VariableId::Kind::kPose, 1}};
  old.jacobian = Eigen::MatrixXd::NullaryExpr(12, 12, [&] { return normal(rng); }) * 5.0;
  old.residual = Eigen::VectorXd::NullaryExpr(12, [&] { return normal(rng); });
  for (const VariableId& id : old.variables) old.linearization_points.push_back(test::perturb(w.state.value(id), 0.01, 0.01, rng));

  const VariableLayout layout(w.state);  // pivot at columns 0-5, poses 1-2, then the extrinsic
  const Eigen::MatrixXd J = numeric_jacobian(w.problem, w.state, layout);
  const Eigen::VectorXd r = pivot_frame_rows(w.problem, w.state);
  Eigen::MatrixXd J_old = Eigen::MatrixXd::Zero(old.jacobian.rows(), layout.size);
  J_old.leftCols(12) = old.jacobian;
  const Eigen::MatrixXd H = J.transpose() * J + J_old.transpose() * J_old;
  const Eigen::VectorXd g = J.transpose() * r + J_old.transpose() * prior_residual(old, w.state);
  Eigen::MatrixXd schur_H;
  Eigen::VectorXd schur_g;
  test::schur_without_first_pose(H, g, schur_H, schur_g);

  const LinearPrior prior = marginalize_frame(w.problem, w.state, 0, kHuberOff);
  // Every map term touches the pivot: the prior holds both later poses and the extrinsic, nothing is left outside it.
  ASSERT_EQ(prior.variables.size(), 3u);
  EXPECT_EQ(prior.variables[0], (VariableId{VariableId::Kind::kPose, 1}));
  EXPECT_EQ(prior.variables[1], (VariableId{VariableId::Kind::kPose, 2}));
  EXPECT_EQ(prior.variables[2], (VariableId{VariableId::Kind::kExtrinsic, 1}));
  const Eigen::MatrixXd prior_H = prior.jacobian.transpose() * prior.jacobian;
  const Eigen::VectorXd prior_g = prior.jacobian.transpose() * prior.residual;
  EXPECT_LT((prior_H - schur_H).norm(), 1e-6 * schur_H.norm());
  EXPECT_LT((prior_g - schur_g).norm(), 1e-6 * schur_g.norm());
}

TEST(AnchoredWindow, ThePivotsPriorConstrainsRelativePosesOnly) {
  // No earlier prior, extrinsics fixed (eq 4.22): moving every pose and the map together moves no residual,
  // so eliminating the pivot leaves a prior that cannot see a motion common to poses 1 and 2.
  const AnchoredWindow w = anchored_window(31, false);
  const LinearPrior prior = marginalize_frame(w.problem, w.state, 0, kHuberOff);
  ASSERT_EQ(prior.variables.size(), 2u);
  EXPECT_EQ(prior.jacobian.rows(), 6);  // 12 columns, rank 12 - 6
  const double scale = prior.jacobian.norm();
  for (int axis = 0; axis < 6; ++axis) {
    Eigen::VectorXd common = Eigen::VectorXd::Zero(12);
    common(axis) = common(6 + axis) = 1.0;
    EXPECT_LT((prior.jacobian * common).norm(), 1e-9 * scale) << axis;
  }
  Eigen::VectorXd relative = Eigen::VectorXd::Zero(12);
  relative(0) = 1.0;  // pose 1 alone along x
  EXPECT_GT((prior.jacobian * relative).norm(), 1e-3 * scale);
}

TEST(AnchoredWindow, ThePivotsOwnFeaturesTouchNoPose) {
  // Eq 4.21: an auxiliary LiDAR's features at the pivot, r(x_p^-1 x_p x_l, p) = r(x_l, p).
  std::mt19937_64 rng(41);
  const std::vector<SE3> poses{SE3(so3_exp(Vec3(0.0, 0.01, 0.2)), Vec3(0.5, -0.3, 0.1)), SE3()};
  const std::vector<SE3> extrinsics{SE3(), SE3(so3_exp(Vec3(0.1, -0.2, 1.0)), Vec3(0.2, 0.3, -0.1))};
  WindowState state = WindowState::make(poses, extrinsics, 0, true);
  WindowProblem world = test::observe(test::room_scene(3, rng), state, 40, rng);
  std::erase_if(world.planes, [](const PlaneCorrespondence& c) { return c.frame != 0 || c.lidar != 1; });
  std::erase_if(world.edges, [](const EdgeCorrespondence& c) { return c.frame != 0 || c.lidar != 1; });
  state.T_base_lidar[1] = test::perturb(state.T_base_lidar[1], 0.02, 0.01, rng);
  WindowProblem anchored = world;
  anchored.anchor = {0, state.T_world_base[0]};
  const VariableLayout layout(state);
  const WindowLinearSystem a = linearize_window(anchored, state, layout, kHuberOff);
  const WindowLinearSystem b = linearize_window(world, state, layout, kHuberOff);
  const int e = layout.extrinsic_offset[1];
  EXPECT_EQ(a.H.topRows(12).norm(), 0.0);  // both poses: exactly nothing
  EXPECT_EQ(a.g.head(12).norm(), 0.0);
  EXPECT_LT((a.H.block<6, 6>(e, e) - b.H.block<6, 6>(e, e)).norm(), 1e-9 * b.H.norm());
  EXPECT_LT((a.g.segment<6>(e) - b.g.segment<6>(e)).norm(), 1e-9 * b.g.norm());
  EXPECT_GT(b.H.topLeftCorner(6, 6).norm(), 1.0);  // against a world map the same features do move pose 0
}

TEST(AnchoredWindow, AFixedPivotAtItsReferenceSolvesAsTheWorldMap) {
  AnchoredWindow w = anchored_window(51, false);
  w.problem.anchor.T_world_base_reference = w.state.T_world_base[0];
  w.state.pose_fixed[0] = true;
  WindowProblem world = w.problem;
  world.anchor = {};
  const WindowSolution anchored = solve_window(w.problem, w.state);
  const WindowSolution plain = solve_window(world, w.state);
  ASSERT_TRUE(anchored.converged && plain.converged);
  for (std::size_t i = 1; i < 3; ++i) EXPECT_LT(test::distance(anchored.state.T_world_base[i], plain.state.T_world_base[i]), 1e-12) << i;
  EXPECT_NEAR(anchored.final_cost, plain.final_cost, 1e-12);
}

}  // namespace
}  // namespace mlidar::slam
