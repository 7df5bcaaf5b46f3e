#pragma once
// Marginalization of the oldest window state into a linear prior (thesis sec
// 4.7.5 and 4.12.2, eq 4.39-4.44), and the shift of the window.
//
// Linearizing the terms that touch the state x_m (its correspondences and the
// current prior) at the current estimate gives H dx = -g over x_m and the
// variables x_r those terms share with it. The Schur complement (eq 4.41)
//   Lambda* = H_rr - H_rm H_mm^-1 H_mr,  g* = g_r - H_rm H_mm^-1 g_m
// is factored (eq 4.43-4.44) as Lambda* = P Psi P^T, J* = Psi^1/2 P^T,
// r* = Psi^-1/2 P^T g*, so that the prior's cost 1/2 |r* + J* dx_r|^2 has the
// same gradient and Hessian in dx_r as the eliminated terms. J* and the
// linearization points are then frozen (first-estimate Jacobians); at a later
// estimate dx_k = Log(X_k X0_k^-1) (see prior_residual).
#include <vector>

#include <Eigen/Core>

#include "mlidar/slam/window_problem.hpp"

namespace mlidar::slam {

/// Eq 4.41 over the columns not in `marginalized` (kept in ascending order).
struct SchurComplement {
  Eigen::MatrixXd H;  ///< Lambda*_rr
  Eigen::VectorXd g;  ///< g*_r
  std::vector<int> kept_columns;
};
/// `marginalized`: column indices into H. H_mm is pseudo-inverted (symmetric_pseudo_inverse): an unobserved
/// direction of the marginalized block contributes nothing.
SchurComplement schur_complement(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const std::vector<int>& marginalized);

/// Eq 4.43-4.44: J*, r* with J*^T J* = H and J*^T r* = g for a symmetric PSD H and g in its range;
/// eigenvalues below 1e-12 x the largest are dropped, so J* has rank(H) rows.
void factor_prior(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Eigen::MatrixXd& jacobian, Eigen::VectorXd& residual);

/// Marginalizes window pose `frame` at `state`: the correspondences on that
/// frame (all of them when the map is anchored at it: the thesis's pivot, sec
/// 4.7.5) and problem.prior are linearized (Huber scale huber_delta_m), the pose
/// is eliminated, and the returned prior holds the variables those terms share
/// with it (fixed blocks are constants and stay out). A fixed pose is a
/// constant: its terms then leave a prior on the other variables alone (to
/// eliminate a pivot that the solves hold fixed, pass a state where it is not).
LinearPrior marginalize_frame(const WindowProblem& problem, const WindowState& state, int frame, double huber_delta_m);

/// Slides the window by one frame, after `prior` = marginalize_frame(problem, state, k, ...) of pose 0 or of
/// the pivot k of an anchored window (pose 0 then left the prior as an earlier pivot, or never was in it):
/// drops pose 0 and its flag (the others move down one index, keeping their
/// flags), appends T_world_base_new as a variable pose, re-indexes the prior's
/// poses (i -> i - 1) into problem.prior, and clears the correspondences and
/// the anchor (the next window's local map makes new ones). Throws std::invalid_argument if the
/// prior still holds pose 0.
void shift_window(WindowProblem& problem, WindowState& state, LinearPrior prior, const SE3& T_world_base_new);

}  // namespace mlidar::slam
