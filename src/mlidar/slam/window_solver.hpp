#pragma once
// Levenberg-Marquardt on the dense normal equations of the sliding window
// (thesis eq 4.20): the state is small (6 (N + 1) + 6 L columns at most), so
// one dense LDLT per iteration costs microseconds; the time goes into summing
// the normal equations over correspondences (window_linearize.hpp).
// Step: (H + lambda diag(H)) dx = -g, X <- Exp(dx) X per variable block;
// accepted when F decreases (lambda / 10), else rejected (lambda x 10).
#include <vector>

#include "mlidar/slam/window_linearize.hpp"
#include "mlidar/slam/window_problem.hpp"

namespace mlidar::slam {

struct WindowSolverConfig {
  int max_iterations = 10;        ///< accepted steps (each one re-linearizes)
  double huber_delta_m = 0.1;     ///< Huber scale on |r|, metres
  double initial_lambda = 1e-6;   ///< Marquardt damping
  double max_lambda = 1e8;        ///< give up (converged = false) past this
  double step_tolerance = 1e-10;  ///< converged when |dx|_inf (m, rad) falls below
};

struct WindowSolution {
  WindowState state;  ///< the estimates (fixed blocks unchanged)
  /// Marginal covariance of each pose (block of H^-1, prior included; [t, r],
  /// left perturbation, m^2 / rad^2); zero for a fixed pose. H is
  /// pseudo-inverted, so a direction no term observes reads zero: see
  /// covariance_valid.
  std::vector<Mat6> pose_covariance;
  bool covariance_valid = false;  ///< H was positive definite
  /// Information of each extrinsic from the map residuals f_M alone (thesis
  /// Algorithm 1, line 3), as the Schur complement of f_M's H onto that block,
  /// every other variable (poses, other extrinsics) eliminated:
  /// H_ee - H_eo H_oo^+ H_oe. Where the LiDAR's residuals lie only on fixed
  /// poses (the thesis's eq 4.21: auxiliary features at the fixed pivot frame)
  /// this equals the H block; where they also move a variable pose, the block
  /// would credit the extrinsic with information that the pose soaks up.
  /// Zero for a fixed extrinsic. Its smallest eigenvalue is Algorithm 1's
  /// lambda (compared with lambda_calib = 70).
  std::vector<Mat6> extrinsic_information;
  double initial_cost = 0.0;  ///< F at the initial state
  double final_cost = 0.0;    ///< F at the solution
  int iterations = 0;         ///< accepted steps
  bool converged = false;
};

/// Solves the window from `initial`. Throws std::invalid_argument on inconsistent sizes/indices.
WindowSolution solve_window(const WindowProblem& problem, const WindowState& initial, const WindowSolverConfig& config = {});

/// X <- Exp(dx_block) X for every variable block of the layout.
void retract(WindowState& state, const VariableLayout& layout, const Eigen::VectorXd& dx);

/// Moore-Penrose inverse of a symmetric PSD matrix (eigenvalues below
/// 1e-12 x the largest count as zero).
Eigen::MatrixXd symmetric_pseudo_inverse(const Eigen::MatrixXd& A);

}  // namespace mlidar::slam
