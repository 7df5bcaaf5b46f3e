#include "mlidar/slam/window_solver.hpp"

#include <algorithm>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace mlidar::slam {
namespace {

constexpr double kRelativeEigenTolerance = 1e-12;

/// Schur complement of H onto the 6x6 block at `offset`: every other column eliminated.
Mat6 schur_onto_block(const Eigen::MatrixXd& H, int offset) {
  const Eigen::Index n = H.rows();
  Eigen::VectorXi others(n - 6);
  for (Eigen::Index k = 0, o = 0; k < n; ++k)
    if (k < offset || k >= offset + 6) others(o++) = static_cast<int>(k);
  const Eigen::MatrixXd H_oo = H(others, others);
  const Eigen::MatrixXd H_eo = H(Eigen::seqN(offset, 6), others);
  return H.block<6, 6>(offset, offset) - H_eo * symmetric_pseudo_inverse(H_oo) * H_eo.transpose();
}

/// `full` is the system linearized at solution.state.
void fill_uncertainty(const WindowProblem& problem, const VariableLayout& layout, double huber_delta, const WindowLinearSystem& full,
                      WindowSolution& solution) {
  const WindowState& state = solution.state;
  solution.final_cost = full.cost;
  Eigen::MatrixXd covariance;
  if (layout.size > 0) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(full.H);
    const double largest = eigen.eigenvalues().maxCoeff();
    solution.covariance_valid = largest > 0.0 && eigen.eigenvalues().minCoeff() > kRelativeEigenTolerance * largest;
    covariance = symmetric_pseudo_inverse(full.H);
  } else {
    solution.covariance_valid = true;
  }
  solution.pose_covariance.assign(state.T_world_base.size(), Mat6::Zero());
  for (std::size_t i = 0; i < state.T_world_base.size(); ++i)
    if (layout.pose_offset[i] >= 0) solution.pose_covariance[i] = covariance.block<6, 6>(layout.pose_offset[i], layout.pose_offset[i]);
  solution.extrinsic_information.assign(state.T_base_lidar.size(), Mat6::Zero());
  const bool calibrating = std::any_of(layout.extrinsic_offset.begin(), layout.extrinsic_offset.end(), [](int o) { return o >= 0; });
  if (!calibrating) return;
  // Algorithm 1 reads f_M's information: the prior's part is taken out again.
  const Eigen::MatrixXd map_H =
      problem.prior.variables.empty() ? full.H : linearize_window(problem, state, layout, huber_delta, PriorTerm::kExclude).H;
  for (std::size_t j = 0; j < state.T_base_lidar.size(); ++j)
    if (layout.extrinsic_offset[j] >= 0) solution.extrinsic_information[j] = schur_onto_block(map_H, layout.extrinsic_offset[j]);
}

}  // namespace

Eigen::MatrixXd symmetric_pseudo_inverse(const Eigen::MatrixXd& A) {
  if (A.size() == 0) return A;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(A);
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double cutoff = kRelativeEigenTolerance * std::max(values.cwiseAbs().maxCoeff(), 0.0);
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(values.size());
  for (Eigen::Index k = 0; k < values.size(); ++k)
    if (values(k) > cutoff && values(k) > 0.0) inverse(k) = 1.0 / values(k);
  return eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
}

void retract(WindowState& state, const VariableLayout& layout, const Eigen::VectorXd& dx) {
  for (std::size_t i = 0; i < state.T_world_base.size(); ++i)
    if (layout.pose_offset[i] >= 0) state.T_world_base[i] = SE3::exp(dx.segment<6>(layout.pose_offset[i])) * state.T_world_base[i];
  for (std::size_t j = 0; j < state.T_base_lidar.size(); ++j)
    if (layout.extrinsic_offset[j] >= 0)
      state.T_base_lidar[j] = SE3::exp(dx.segment<6>(layout.extrinsic_offset[j])) * state.T_base_lidar[j];
}

WindowSolution solve_window(const WindowProblem& problem, const WindowState& initial, const WindowSolverConfig& config) {
  check_problem(problem, initial);
  const VariableLayout layout(initial);
  WindowSolution solution;
  solution.state = initial;
  WindowLinearSystem system = linearize_window(problem, solution.state, layout, config.huber_delta_m);
  solution.initial_cost = system.cost;
  double lambda = config.initial_lambda;
  solution.converged = layout.size == 0;
  while (!solution.converged && solution.iterations < config.max_iterations) {
    Eigen::MatrixXd damped = system.H;
    damped.diagonal() += lambda * system.H.diagonal().cwiseMax(1e-12);
    const Eigen::VectorXd dx = damped.ldlt().solve(-system.g);
    if (!dx.allFinite()) break;
    if (dx.lpNorm<Eigen::Infinity>() < config.step_tolerance) {
      solution.converged = true;
      break;
    }
    WindowState candidate = solution.state;
    retract(candidate, layout, dx);
    if (window_cost(problem, candidate, config.huber_delta_m) <= system.cost) {
      solution.state = std::move(candidate);
      system = linearize_window(problem, solution.state, layout, config.huber_delta_m);
      ++solution.iterations;
      lambda = std::max(lambda / 10.0, 1e-12);
    } else if ((lambda *= 10.0) > config.max_lambda) {
      break;
    }
  }
  fill_uncertainty(problem, layout, config.huber_delta_m, system, solution);
  return solution;
}

}  // namespace mlidar::slam
