#pragma once
// The sliding-window problem of window_problem.hpp (eq 4.20-4.22: plane and
// edge terms of LiDAR-frame features against world planes and lines, Huber
// loss, fixed and variable poses and extrinsics) solved with Ceres: each
// variable is one 7-double block [qx qy qz qw tx ty tz] on
// ceres::ProductManifold<EigenQuaternionManifold, EuclideanManifold<3>>
// (SO(3) x R^3), residuals by automatic differentiation. It exists to compare
// against the hand-written solver (window_solver.hpp), as issue 9 asks:
// docs/benchmarks.md "Solver: Ceres vs hand-written". The marginalization
// prior and the map anchored at the pivot are not modelled (the compared
// problems carry neither).
#include "mlidar/slam/window_problem.hpp"

namespace mlidar::slam {

struct CeresWindowOptions {
  double huber_delta_m = 0.1;  ///< the same Huber scale as WindowSolverConfig
  int max_iterations = 10;
  bool dense_qr = false;  ///< DENSE_QR instead of DENSE_NORMAL_CHOLESKY
};

struct CeresWindowResult {
  WindowState state;
  double initial_cost = 0.0;  ///< 1/2 sum rho(|r|^2), as window_cost
  double final_cost = 0.0;
  int iterations = 0;  ///< Ceres's successful steps
  bool converged = false;
};

/// Throws std::invalid_argument for an inconsistent problem or one with a prior or an anchored map.
CeresWindowResult solve_window_ceres(const WindowProblem& problem, const WindowState& initial, const CeresWindowOptions& options = {});

}  // namespace mlidar::slam
