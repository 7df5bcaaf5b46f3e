#pragma once
// Linearization of the window's cost (thesis eq 4.20):
//   F(X) = 1/2 sum rho(|r_c|^2) + 1/2 |r* + J* dx|^2
// with rho the Huber loss of scale delta (rho(s) = s inside delta^2,
// 2 delta sqrt(s) - delta^2 outside) and the normal equations of iteratively
// reweighted Gauss-Newton, H dx = -g, H = sum w J^T J, g = sum w J^T r,
// w = rho'(|r|^2) (1 inside delta, delta / |r| outside).
//
// Each residual is a sum of scalar rows r = sum_k n_k s_k over orthonormal
// directions n_k, s_k = n_k^T (q - a), so that |r|^2 = sum s_k^2 and
// J^T J = sum grad_k grad_k^T (rank-one updates):
//   plane (eq 4.7): one row, n = the plane normal, s = n^T q + d;
//   edge  (eq 4.8): two rows along an orthonormal basis n_1, n_2 of the plane
//     normal to the line: r = (I - u u^T)(q - a), the point's offset from the
//     line. Eq 4.8 stacks the residuals of two orthogonal planes through the
//     line; their sum is this r, with the same norm, J^T J and J^T r, and unlike
//     the stacked form it is differentiable on the line too.
// Gradients for q = T_world_base * T_base_lidar * x, y = T_base_lidar * x,
// left perturbations of both (tangent [t, r]):
//   ds/d(pose)      = [n, q x n]                       (dq = [I, -[q]x] d)
//   ds/d(extrinsic) = [v, y x v],  v = R_world_base^T n (dq = R [I, -[y]x] e)
// With an anchored map (window_problem.hpp) the plane or line is first moved by
// D = T_p T0_p^-1 (n' = R_D n, d' = d - n'^T t_D; a' = D a, u' = R_D u) and the
// rows above use n'; the pivot's gradient is then -ds/d(pose): s = n^T D^-1 q + d
// and a left perturbation of T_p turns D^-1 q into D^-1 Exp(-e) q. A feature of
// the pivot itself has zero pose gradient in total (T_p^-1 T_p cancels).
#include <array>

#include <Eigen/Core>

#include "mlidar/slam/window_problem.hpp"

namespace mlidar::slam {

using Vec12 = Eigen::Matrix<double, 12, 1>;

/// Scalar rows of one residual at the current estimate.
struct ResidualRows {
  int count = 0;                   ///< 1 (plane) or 2 (edge)
  std::array<Vec3, 2> directions;  ///< n_k, orthonormal, world frame
  std::array<double, 2> values{};  ///< s_k, metres
  std::array<Vec12, 2> gradients;  ///< [ds/d(pose), ds/d(extrinsic)]

  Vec3 residual() const;        ///< r = sum n_k s_k
  double squared_norm() const;  ///< |r|^2
};

/// `T_map_motion`: D of an anchored map (map_motion), identity for a world map.
ResidualRows plane_rows(const PlaneCorrespondence& c, const SE3& T_world_base, const SE3& T_base_lidar,
                        const SE3& T_map_motion = SE3::identity());
ResidualRows edge_rows(const EdgeCorrespondence& c, const SE3& T_world_base, const SE3& T_base_lidar,
                       const SE3& T_map_motion = SE3::identity());

/// Huber loss rho(s) of a squared norm s (see above).
double huber_loss(double squared_norm, double delta);

/// Normal equations over the layout's variables (fixed blocks are constants).
struct WindowLinearSystem {
  Eigen::MatrixXd H;  ///< sum w J^T J (+ J*^T J*), layout.size square
  Eigen::VectorXd g;  ///< sum w J^T r (+ J*^T (r* + J* dx))
  double cost = 0.0;  ///< F(X), including the prior when it is included
};

enum class PriorTerm { kInclude, kExclude };

/// Normal equations at `state`, summed over correspondences with tbb::parallel_deterministic_reduce (fixed chunks:
/// the same sums whatever the thread count).
WindowLinearSystem linearize_window(const WindowProblem& problem, const WindowState& state, const VariableLayout& layout,
                                    double huber_delta, PriorTerm prior = PriorTerm::kInclude);
/// F(X) alone (cheaper: no Jacobians).
double window_cost(const WindowProblem& problem, const WindowState& state, double huber_delta);

/// The prior's residual r* + J* dx at `state` (dx from the linearization points).
Eigen::VectorXd prior_residual(const LinearPrior& prior, const WindowState& state);

}  // namespace mlidar::slam
