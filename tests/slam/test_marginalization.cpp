// Marginalization (eq 4.39-4.44) against a dense problem built by hand: the
// prior equals the Schur complement of the full normal equations, and solving
// the reduced problem gives the full problem's solution for the kept variables.
#include <random>

#include <gtest/gtest.h>

#include "mlidar/slam/marginalization.hpp"
#include "mlidar/slam/window_linearize.hpp"
#include "mlidar/slam/window_solver.hpp"
#include "slam/window_scene.hpp"

namespace mlidar::slam {
namespace {

using test::kHuberOff;

/// Three poses (all variables), two LiDARs (the auxiliary one a variable), a few
/// features per frame, the state perturbed from the truth (non-zero residuals),
/// and an earlier prior on pose 0, pose 1 and the auxiliary extrinsic.
struct SmallWindow {
  WindowState state;
  WindowProblem problem;
};

SmallWindow small_window(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<SE3> poses{SE3(so3_exp(Vec3(0.0, 0.0, 0.1)), Vec3(0.0, 0.0, 0.0)),
                               SE3(so3_exp(Vec3(0.02, 0.0, 0.3)), Vec3(1.0, 0.2, 0.0)),
                               SE3(so3_exp(Vec3(0.0, -0.03, 0.5)), Vec3(2.0, 0.5, 0.1))};
  const std::vector<SE3> extrinsics{SE3(), SE3(so3_exp(Vec3(0.2, 0.1, 1.5)), Vec3(0.3, -0.4, 0.2))};
  SmallWindow window;
  const WindowState truth = WindowState::make(poses, extrinsics, 0, true);
  window.problem = test::observe(test::room_scene(3, rng), truth, 12, rng);
  window.state = truth;
  for (SE3& T : window.state.T_world_base) T = test::perturb(T, 0.03, 0.01, rng);
  window.state.T_base_lidar[1] = test::perturb(window.state.T_base_lidar[1], 0.02, 0.01, rng);
  LinearPrior& prior = window.problem.prior;
  prior.variables = {{VariableId::Kind::kPose, 0}, {VariableId::Kind::kPose, 1}, {VariableId::Kind::kExtrinsic, 1}};
  std::normal_distribution<double> normal(0.0, 1.0);
  prior.jacobian = Eigen::MatrixXd::NullaryExpr(18, 18, [&] { return normal(rng); }) * 10.0;
  prior.residual = Eigen::VectorXd::NullaryExpr(18, [&] { return normal(rng); });
  for (const VariableId& id : prior.variables) prior.linearization_points.push_back(test::perturb(window.state.value(id), 0.01, 0.01, rng));
  return window;
}

/// Dense J (one row per scalar residual row, columns = layout) and r, written out per row.
void dense_jacobian(const WindowProblem& problem, const WindowState& state, const VariableLayout& layout, Eigen::MatrixXd& J,
                    Eigen::VectorXd& r) {
  std::vector<std::tuple<ResidualRows, int, int>> all;
  for (const auto& c : problem.planes)
    all.emplace_back(plane_rows(c, state.T_world_base[c.frame], state.T_base_lidar[c.lidar]), c.frame, c.lidar);
  for (const auto& c : problem.edges)
    all.emplace_back(edge_rows(c, state.T_world_base[c.frame], state.T_base_lidar[c.lidar]), c.frame, c.lidar);
  J = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(2 * all.size()), layout.size);
  r = Eigen::VectorXd::Zero(J.rows());
  Eigen::Index row = 0;
  for (const auto& [rows, frame, lidar] : all)
    for (std::size_t k = 0; k < static_cast<std::size_t>(rows.count); ++k, ++row) {
      r(row) = rows.values[k];
      if (const int o = layout.pose_offset[frame]; o >= 0) J.block<1, 6>(row, o) = rows.gradients[k].head<6>().transpose();
      if (const int o = layout.extrinsic_offset[lidar]; o >= 0) J.block<1, 6>(row, o) = rows.gradients[k].tail<6>().transpose();
    }
}

/// Full dense normal equations: map rows plus the existing prior (J* embedded, r* + J* dx).
void full_system(const SmallWindow& w, const VariableLayout& layout, Eigen::MatrixXd& H, Eigen::VectorXd& g) {
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  dense_jacobian(w.problem, w.state, layout, J, r);
  const LinearPrior& prior = w.problem.prior;
  Eigen::MatrixXd J_prior = Eigen::MatrixXd::Zero(prior.jacobian.rows(), layout.size);
  for (std::size_t k = 0; k < prior.variables.size(); ++k)
    J_prior.middleCols<6>(layout.offset(prior.variables[k])) = prior.jacobian.middleCols<6>(static_cast<Eigen::Index>(6 * k));
  const Eigen::VectorXd r_prior = prior_residual(prior, w.state);
  H = J.transpose() * J + J_prior.transpose() * J_prior;
  g = J.transpose() * r + J_prior.transpose() * r_prior;
}

/// The new prior's normal equations embedded in `layout`'s columns.
void prior_system(const LinearPrior& prior, const VariableLayout& layout, Eigen::MatrixXd& H, Eigen::VectorXd& g) {
  H = Eigen::MatrixXd::Zero(layout.size, layout.size);
  g = Eigen::VectorXd::Zero(layout.size);
  for (std::size_t a = 0; a < prior.variables.size(); ++a) {
    const auto Ja = prior.jacobian.middleCols<6>(static_cast<Eigen::Index>(6 * a));
    g.segment<6>(layout.offset(prior.variables[a])) = Ja.transpose() * prior.residual;
    for (std::size_t b = 0; b < prior.variables.size(); ++b)
      H.block<6, 6>(layout.offset(prior.variables[a]), layout.offset(prior.variables[b])) =
          Ja.transpose() * prior.jacobian.middleCols<6>(static_cast<Eigen::Index>(6 * b));
  }
}

TEST(Marginalization, PriorEqualsSchurComplementOfTheFullProblem) {
  const SmallWindow w = small_window(61);
  const VariableLayout layout(w.state);  // pose 0 at columns 0-5
  Eigen::MatrixXd H;
  Eigen::VectorXd g;
  full_system(w, layout, H, g);
  const Eigen::Index n = layout.size;
  Eigen::MatrixXd schur_H;
  Eigen::VectorXd schur_g;
  test::schur_without_first_pose(H, g, schur_H, schur_g);

  const LinearPrior prior = marginalize_frame(w.problem, w.state, 0, kHuberOff);
  ASSERT_EQ(prior.variables.size(), 2u);  // pose 1 (through the old prior) and the auxiliary extrinsic
  EXPECT_EQ(prior.variables[0], (VariableId{VariableId::Kind::kPose, 1}));
  EXPECT_EQ(prior.variables[1], (VariableId{VariableId::Kind::kExtrinsic, 1}));
  EXPECT_EQ(prior.linearization_points[1].matrix(), w.state.T_base_lidar[1].matrix());
  // The Schur complement of the full problem = new prior + the terms that never touched pose 0.
  Eigen::MatrixXd prior_H;
  Eigen::VectorXd prior_g;
  prior_system(prior, layout, prior_H, prior_g);
  WindowProblem rest = w.problem;
  rest.prior = {};
  std::erase_if(rest.planes, [](const PlaneCorrespondence& c) { return c.frame == 0; });
  std::erase_if(rest.edges, [](const EdgeCorrespondence& c) { return c.frame == 0; });
  Eigen::MatrixXd J_rest;
  Eigen::VectorXd r_rest;
  dense_jacobian(rest, w.state, layout, J_rest, r_rest);
  const Eigen::MatrixXd reduced_H = (prior_H + J_rest.transpose() * J_rest).bottomRightCorner(n - 6, n - 6);
  const Eigen::VectorXd reduced_g = (prior_g + J_rest.transpose() * r_rest).tail(n - 6);
  EXPECT_LT((reduced_H - schur_H).norm(), 1e-9 * schur_H.norm());
  EXPECT_LT((reduced_g - schur_g).norm(), 1e-9 * schur_g.norm());

  // Solving the reduced problem gives the full linear problem's kept variables.
  const Eigen::VectorXd full_dx = H.ldlt().solve(-g);
  const Eigen::VectorXd reduced_dx = reduced_H.ldlt().solve(-reduced_g);
  EXPECT_LT((full_dx.tail(n - 6) - reduced_dx).norm(), 1e-9 * full_dx.norm());
}

TEST(Marginalization, SchurComplementHelperMatchesExplicitInverse) {
  std::mt19937_64 rng(71);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(20, 12, [&] { return normal(rng); });
  const Eigen::MatrixXd H = A.transpose() * A;
  const Eigen::VectorXd g = Eigen::VectorXd::NullaryExpr(12, [&] { return normal(rng); });
  const std::vector<int> m{2, 7, 9};
  const SchurComplement s = schur_complement(H, g, m);
  ASSERT_EQ(s.kept_columns.size(), 9u);
  const Eigen::MatrixXd H_mm_inv = H(m, m).inverse();
  const Eigen::MatrixXd H_rm = H(s.kept_columns, m);
  EXPECT_LT((s.H - (H(s.kept_columns, s.kept_columns) - H_rm * H_mm_inv * H_rm.transpose())).norm(), 1e-9 * H.norm());
  EXPECT_LT((s.g - (g(s.kept_columns) - H_rm * H_mm_inv * g(m))).norm(), 1e-9 * g.norm());
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  factor_prior(s.H, s.g, J, r);  // eq 4.44
  EXPECT_LT((J.transpose() * J - s.H).norm(), 1e-9 * s.H.norm());
  EXPECT_LT((J.transpose() * r - s.g).norm(), 1e-9 * s.g.norm());
}

TEST(Marginalization, FixedPoseLeavesAPriorOnTheExtrinsicAlone) {
  SmallWindow w = small_window(81);
  w.problem.prior = {};
  w.state.pose_fixed[0] = true;
  const LinearPrior prior = marginalize_frame(w.problem, w.state, 0, kHuberOff);
  ASSERT_EQ(prior.variables.size(), 1u);
  EXPECT_EQ(prior.variables[0], (VariableId{VariableId::Kind::kExtrinsic, 1}));
  // Equal to the extrinsic block of the frame-0 terms.
  WindowProblem frame0 = w.problem;
  std::erase_if(frame0.planes, [](const PlaneCorrespondence& c) { return c.frame != 0; });
  std::erase_if(frame0.edges, [](const EdgeCorrespondence& c) { return c.frame != 0; });
  const VariableLayout layout(w.state);
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  dense_jacobian(frame0, w.state, layout, J, r);
  const int e = layout.extrinsic_offset[1];
  const Mat6 block = (J.transpose() * J).block<6, 6>(e, e);
  EXPECT_LT((prior.jacobian.transpose() * prior.jacobian - block).norm(), 1e-9 * block.norm());
  EXPECT_LT((prior.jacobian.transpose() * prior.residual - (J.transpose() * r).segment<6>(e)).norm(), 1e-9 * block.norm());
}

TEST(Marginalization, FixedPoseWithFixedExtrinsicsLeavesNoPrior) {
  // Eq 4.22: every block the frame-0 terms touch is a constant (a crash before: a 0 x 0 Schur complement).
  SmallWindow w = small_window(83);
  w.problem.prior = {};
  w.state.pose_fixed[0] = true;
  set_extrinsic_mode(w.state, ExtrinsicMode::kFixed);
  const LinearPrior prior = marginalize_frame(w.problem, w.state, 0, kHuberOff);
  EXPECT_TRUE(prior.variables.empty());
  EXPECT_EQ(prior.jacobian.rows(), 0);
}

TEST(Marginalization, ShiftReindexesThePriorAndKeepsItsValue) {
  SmallWindow w = small_window(91);
  const LinearPrior prior = marginalize_frame(w.problem, w.state, 0, kHuberOff);
  const Eigen::VectorXd before = prior_residual(prior, w.state);
  const SE3 newest(so3_exp(Vec3(0.0, 0.0, 0.9)), Vec3(3.0, 0.8, 0.1));
  WindowState state = w.state;
  WindowProblem problem = w.problem;
  shift_window(problem, state, prior, newest);
  ASSERT_EQ(state.T_world_base.size(), 3u);
  EXPECT_EQ(state.T_world_base[0].matrix(), w.state.T_world_base[1].matrix());
  EXPECT_EQ(state.T_world_base[2].matrix(), newest.matrix());
  EXPECT_FALSE(state.pose_fixed[2]);
  EXPECT_TRUE(problem.planes.empty() && problem.edges.empty());
  EXPECT_EQ(problem.prior.variables[0], (VariableId{VariableId::Kind::kPose, 0}));
  EXPECT_LT((prior_residual(problem.prior, state) - before).norm(), 1e-12);
  EXPECT_LT((before - prior.residual).norm(), 1e-12);                                          // dx = 0 at the linearization point
  EXPECT_THROW(shift_window(problem, state, w.problem.prior, newest), std::invalid_argument);  // still holds pose 0
}

TEST(Marginalization, SlidingThroughASequenceKeepsTheTruth) {
  // Solve, marginalize the oldest pose, shift, repeat: with noise-free features every window
  // lands on the truth, the prior included (it is linearized at the truth after the first solve).
  std::mt19937_64 rng(101);
  const test::WindowScene scene = test::room_scene(6, rng);
  const auto true_pose = [](int k) { return SE3(so3_exp(Vec3(0.01 * k, 0.0, 0.2 * k)), Vec3(0.7 * k, 0.1 * k * k, 0.0)); };
  const SE3 aux(so3_exp(Vec3(0.3, -0.2, 2.0)), Vec3(0.4, 0.6, -0.1));
  WindowState state = WindowState::make({true_pose(0), true_pose(1), true_pose(2)}, {SE3(), test::perturb(aux, 0.05, 0.05, rng)}, 1, true);
  state.T_world_base[2] = test::perturb(state.T_world_base[2], 0.1, 0.03, rng);
  WindowProblem problem;
  for (int window = 0; window < 4; ++window) {
    WindowState truth = state;
    for (int i = 0; i < 3; ++i) truth.T_world_base[static_cast<std::size_t>(i)] = true_pose(window + i);
    truth.T_base_lidar[1] = aux;
    const WindowProblem observed = test::observe(scene, truth, 150, rng);
    problem.planes = observed.planes;
    problem.edges = observed.edges;
    const WindowSolution solution = solve_window(problem, state);
    EXPECT_TRUE(solution.converged) << window;
    EXPECT_LT(test::distance(solution.state.T_base_lidar[1], aux), 1e-6) << window;
    for (int i = 0; i < 3; ++i)
      EXPECT_LT(test::distance(solution.state.T_world_base[static_cast<std::size_t>(i)], true_pose(window + i)), 1e-6)
          << window << " " << i;
    EXPECT_EQ(problem.prior.variables.empty(), window == 0);
    state = solution.state;
    LinearPrior prior = marginalize_frame(problem, state, 0, 0.1);
    shift_window(problem, state, std::move(prior), test::perturb(true_pose(window + 3), 0.1, 0.03, rng));
  }
}

}  // namespace
}  // namespace mlidar::slam
