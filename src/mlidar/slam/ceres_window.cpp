#include "mlidar/slam/ceres_window.hpp"

#include <array>
#include <stdexcept>
#include <vector>

#include <ceres/ceres.h>

namespace mlidar::slam {
namespace {

using Block = std::array<double, 7>;  ///< [qx qy qz qw tx ty tz]
using SE3Manifold = ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;

Block to_block(const SE3& T) {
  const Quat q = T.rotation().normalized();
  const Vec3& t = T.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

SE3 from_block(const Block& b) { return SE3(Quat(b[3], b[0], b[1], b[2]).normalized(), Vec3(b[4], b[5], b[6])); }

/// q = T_world_base (T_base_lidar x) for blocks in the Block layout.
template <typename T>
Eigen::Matrix<T, 3, 1> world_point(const T* pose, const T* extrinsic, const Vec3& x) {
  const Eigen::Quaternion<T> R_wb(pose[3], pose[0], pose[1], pose[2]);
  const Eigen::Quaternion<T> R_bl(extrinsic[3], extrinsic[0], extrinsic[1], extrinsic[2]);
  const Eigen::Matrix<T, 3, 1> y = R_bl * x.cast<T>() + Eigen::Matrix<T, 3, 1>(extrinsic[4], extrinsic[5], extrinsic[6]);
  return R_wb * y + Eigen::Matrix<T, 3, 1>(pose[4], pose[5], pose[6]);
}

/// Eq 4.7 as a scalar row: n^T q + d.
struct PlaneTerm {
  Vec3 x, n;
  double d;
  template <typename T>
  bool operator()(const T* pose, const T* extrinsic, T* residual) const {
    const Eigen::Matrix<T, 3, 1> q = world_point(pose, extrinsic, x);
    residual[0] = n.cast<T>().dot(q) + T(d);
    return true;
  }
};

/// Eq 4.8 as two rows: the offset from the line along two unit normals of it
/// (the same normals as window_linearize's rows).
struct EdgeTerm {
  Vec3 x, a, n1, n2;
  template <typename T>
  bool operator()(const T* pose, const T* extrinsic, T* residual) const {
    const Eigen::Matrix<T, 3, 1> offset = world_point(pose, extrinsic, x) - a.cast<T>();
    residual[0] = n1.cast<T>().dot(offset);
    residual[1] = n2.cast<T>().dot(offset);
    return true;
  }
};

}  // namespace

CeresWindowResult solve_window_ceres(const WindowProblem& problem, const WindowState& initial, const CeresWindowOptions& options) {
  check_problem(problem, initial);
  if (!problem.prior.variables.empty()) throw std::invalid_argument("solve_window_ceres: a marginalization prior is not modelled");
  if (problem.anchor.frame >= 0) throw std::invalid_argument("solve_window_ceres: a map anchored at a window pose is not modelled");
  std::vector<Block> poses, extrinsics;
  for (const SE3& T : initial.T_world_base) poses.push_back(to_block(T));
  for (const SE3& T : initial.T_base_lidar) extrinsics.push_back(to_block(T));

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem ceres_problem(problem_options);
  SE3Manifold manifold;
  ceres::HuberLoss huber(options.huber_delta_m);  // rho(s) = s, or 2 delta sqrt(s) - delta^2: huber_loss of window_linearize
  for (const PlaneCorrespondence& c : problem.planes) {
    auto* cost =
        new ceres::AutoDiffCostFunction<PlaneTerm, 1, 7, 7>(new PlaneTerm{c.point_lidar, c.plane_world.normal, c.plane_world.offset});
    ceres_problem.AddResidualBlock(cost, &huber, poses[static_cast<std::size_t>(c.frame)].data(),
                                   extrinsics[static_cast<std::size_t>(c.lidar)].data());
  }
  for (const EdgeCorrespondence& c : problem.edges) {
    const Vec3 n1 = c.line_direction_world.unitOrthogonal();
    const Vec3 n2 = c.line_direction_world.cross(n1).normalized();
    auto* cost = new ceres::AutoDiffCostFunction<EdgeTerm, 2, 7, 7>(new EdgeTerm{c.point_lidar, c.line_point_world, n1, n2});
    ceres_problem.AddResidualBlock(cost, &huber, poses[static_cast<std::size_t>(c.frame)].data(),
                                   extrinsics[static_cast<std::size_t>(c.lidar)].data());
  }
  const auto configure = [&](Block& block, bool fixed) {
    if (!ceres_problem.HasParameterBlock(block.data())) return;
    ceres_problem.SetManifold(block.data(), &manifold);
    if (fixed) ceres_problem.SetParameterBlockConstant(block.data());
  };
  for (std::size_t i = 0; i < poses.size(); ++i) configure(poses[i], initial.pose_fixed[i]);
  for (std::size_t j = 0; j < extrinsics.size(); ++j) configure(extrinsics[j], initial.extrinsic_fixed[j]);

  ceres::Solver::Options solver;
  solver.linear_solver_type = options.dense_qr ? ceres::DENSE_QR : ceres::DENSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.function_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-14;
  solver.parameter_tolerance = 1e-10;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &ceres_problem, &summary);

  CeresWindowResult result;
  result.state = initial;
  for (std::size_t i = 0; i < poses.size(); ++i) result.state.T_world_base[i] = from_block(poses[i]);
  for (std::size_t j = 0; j < extrinsics.size(); ++j) result.state.T_base_lidar[j] = from_block(extrinsics[j]);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = summary.num_successful_steps;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  return result;
}

}  // namespace mlidar::slam
