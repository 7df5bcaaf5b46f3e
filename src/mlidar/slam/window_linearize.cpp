#include "mlidar/slam/window_linearize.hpp"

#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

namespace mlidar::slam {
namespace {

using Mat12 = Eigen::Matrix<double, 12, 12>;

/// A (frame, lidar) pair's transforms as matrices, built once per pair.
struct PairTransform {
  Mat3 R_world_base;
  Vec3 t_world_base;
  Mat3 R_base_lidar;
  Vec3 t_base_lidar;

  PairTransform(const SE3& T_world_base, const SE3& T_base_lidar)
      : R_world_base(T_world_base.rotation_matrix()),
        t_world_base(T_world_base.translation()),
        R_base_lidar(T_base_lidar.rotation_matrix()),
        t_base_lidar(T_base_lidar.translation()) {}
};

/// D of an anchored map as matrices; `moved` false for a world map (nothing to apply).
struct MapMotion {
  bool moved = false;
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();

  MapMotion() = default;
  explicit MapMotion(const SE3& D) : moved(true), R(D.rotation_matrix()), t(D.translation()) {}
  PlaneCoefficients plane(const PlaneCoefficients& p) const {
    if (!moved) return p;
    const Vec3 n = R * p.normal;
    return {n, p.offset - n.dot(t)};
  }
  Vec3 point(const Vec3& a) const { return moved ? Vec3(R * a + t) : a; }
  Vec3 direction(const Vec3& u) const { return moved ? Vec3(R * u) : u; }
};

MapMotion motion_of(const WindowProblem& problem, const WindowState& state) {
  return problem.anchor.frame < 0 ? MapMotion() : MapMotion(map_motion(problem.anchor, state));
}

/// One row s = n^T q + offset with its pose and extrinsic gradients.
void add_row(ResidualRows& rows, const Vec3& n, double offset, const Vec3& q, const Vec3& y, const Mat3& R_world_base) {
  const auto k = static_cast<std::size_t>(rows.count++);
  rows.directions[k] = n;
  rows.values[k] = n.dot(q) + offset;
  const Vec3 v = R_world_base.transpose() * n;
  rows.gradients[k] << n, q.cross(n), v, y.cross(v);
}

/// |r|^2 alone (for the cost): plane (n^T q + d)^2, edge |(I - u u^T)(q - a)|^2.
double squared_norm_of(const PlaneCorrespondence& c, const PairTransform& T, const MapMotion& motion) {
  const Vec3 q = T.R_world_base * (T.R_base_lidar * c.point_lidar + T.t_base_lidar) + T.t_world_base;
  const PlaneCoefficients plane = motion.plane(c.plane_world);
  const double s = plane.normal.dot(q) + plane.offset;
  return s * s;
}

double squared_norm_of(const EdgeCorrespondence& c, const PairTransform& T, const MapMotion& motion) {
  const Vec3 u = motion.direction(c.line_direction_world);
  const Vec3 d = T.R_world_base * (T.R_base_lidar * c.point_lidar + T.t_base_lidar) + T.t_world_base - motion.point(c.line_point_world);
  return (d - u.dot(d) * u).squaredNorm();
}

ResidualRows rows_of(const PlaneCorrespondence& c, const PairTransform& T, const MapMotion& motion) {
  const Vec3 y = T.R_base_lidar * c.point_lidar + T.t_base_lidar;
  const Vec3 q = T.R_world_base * y + T.t_world_base;
  const PlaneCoefficients plane = motion.plane(c.plane_world);
  ResidualRows rows;
  add_row(rows, plane.normal, plane.offset, q, y, T.R_world_base);
  return rows;
}

ResidualRows rows_of(const EdgeCorrespondence& c, const PairTransform& T, const MapMotion& motion) {
  const Vec3 y = T.R_base_lidar * c.point_lidar + T.t_base_lidar;
  const Vec3 q = T.R_world_base * y + T.t_world_base;
  const Vec3 u = motion.direction(c.line_direction_world);
  const Vec3 a = motion.point(c.line_point_world);
  const Vec3 n1 = u.unitOrthogonal();
  const Vec3 n2 = u.cross(n1).normalized();
  ResidualRows rows;
  add_row(rows, n1, -n1.dot(a), q, y, T.R_world_base);
  add_row(rows, n2, -n2.dot(a), q, y, T.R_world_base);
  return rows;
}

/// Sums of w J^T J and w J^T r per (frame, lidar) pair, 12 columns [pose, extrinsic].
struct PairSums {
  std::vector<Mat12> H;
  std::vector<Vec12> g;
  double cost = 0.0;

  explicit PairSums(std::size_t pairs) : H(pairs, Mat12::Zero()), g(pairs, Vec12::Zero()) {}
  PairSums& operator+=(const PairSums& o) {
    for (std::size_t k = 0; k < H.size(); ++k) {
      H[k] += o.H[k];
      g[k] += o.g[k];
    }
    cost += o.cost;
    return *this;
  }
};

/// Visits every correspondence (in parallel) and folds it with `fold(c, transform, motion, pair, sums)`.
template <typename Fold>
PairSums reduce_rows(const WindowProblem& problem, const WindowState& state, std::size_t pairs, const Fold& fold) {
  const std::size_t lidars = state.T_base_lidar.size();
  const MapMotion motion = motion_of(problem, state);
  std::vector<PairTransform> transforms;
  for (const SE3& T_world_base : state.T_world_base)
    for (const SE3& T_base_lidar : state.T_base_lidar) transforms.emplace_back(T_world_base, T_base_lidar);
  const std::size_t total = problem.planes.size() + problem.edges.size();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, total, 512), PairSums(pairs),
      [&](const tbb::blocked_range<std::size_t>& range, PairSums sums) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const auto visit = [&](const auto& c) {
            const std::size_t pair = static_cast<std::size_t>(c.frame) * lidars + static_cast<std::size_t>(c.lidar);
            fold(c, transforms[pair], motion, pair, sums);
          };
          if (i < problem.planes.size()) {
            visit(problem.planes[i]);
          } else {
            visit(problem.edges[i - problem.planes.size()]);
          }
        }
        return sums;
      },
      [](PairSums a, const PairSums& b) { return a += b; });
}

/// Adds a 12-column pair block into the layout's system (fixed blocks dropped). The gradient is
/// [ds/d(pose), ds/d(extrinsic), -ds/d(pose)] over (pose, extrinsic, anchor): the anchor's
/// blocks are the pose's with the sign of each anchor factor (anchor_offset -1: a world map or a fixed pivot).
void scatter_pair(const Mat12& H_pair, const Vec12& g_pair, int pose_offset, int extrinsic_offset, int anchor_offset,
                  WindowLinearSystem& system) {
  const std::array<int, 3> offsets{pose_offset, extrinsic_offset, anchor_offset};
  const std::array<Eigen::Index, 3> source{0, 6, 0};
  const std::array<double, 3> sign{1.0, 1.0, -1.0};
  for (std::size_t a = 0; a < 3; ++a) {
    if (offsets[a] < 0) continue;
    system.g.segment<6>(offsets[a]) += sign[a] * g_pair.segment<6>(source[a]);
    for (std::size_t b = 0; b < 3; ++b)
      if (offsets[b] >= 0) system.H.block<6, 6>(offsets[a], offsets[b]) += (sign[a] * sign[b]) * H_pair.block<6, 6>(source[a], source[b]);
  }
}

void add_prior(const LinearPrior& prior, const WindowState& state, const VariableLayout& layout, WindowLinearSystem& system) {
  if (prior.variables.empty()) return;
  const Eigen::VectorXd r = prior_residual(prior, state);
  system.cost += 0.5 * r.squaredNorm();
  for (std::size_t a = 0; a < prior.variables.size(); ++a) {
    const int oa = layout.offset(prior.variables[a]);
    if (oa < 0) continue;
    const auto Ja = prior.jacobian.middleCols<6>(static_cast<Eigen::Index>(6 * a));
    system.g.segment<6>(oa) += Ja.transpose() * r;
    for (std::size_t b = 0; b < prior.variables.size(); ++b) {
      const int ob = layout.offset(prior.variables[b]);
      if (ob >= 0) system.H.block<6, 6>(oa, ob) += Ja.transpose() * prior.jacobian.middleCols<6>(static_cast<Eigen::Index>(6 * b));
    }
  }
}

}  // namespace

Vec3 ResidualRows::residual() const {
  Vec3 r = Vec3::Zero();
  for (std::size_t k = 0; k < static_cast<std::size_t>(count); ++k) r += values[k] * directions[k];
  return r;
}

double ResidualRows::squared_norm() const {
  double sum = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(count); ++k) sum += values[k] * values[k];
  return sum;
}

ResidualRows plane_rows(const PlaneCorrespondence& c, const SE3& T_world_base, const SE3& T_base_lidar, const SE3& T_map_motion) {
  return rows_of(c, PairTransform(T_world_base, T_base_lidar), MapMotion(T_map_motion));
}

ResidualRows edge_rows(const EdgeCorrespondence& c, const SE3& T_world_base, const SE3& T_base_lidar, const SE3& T_map_motion) {
  return rows_of(c, PairTransform(T_world_base, T_base_lidar), MapMotion(T_map_motion));
}

double huber_loss(double squared_norm, double delta) {
  return squared_norm <= delta * delta ? squared_norm : 2.0 * delta * std::sqrt(squared_norm) - delta * delta;
}

WindowLinearSystem linearize_window(const WindowProblem& problem, const WindowState& state, const VariableLayout& layout,
                                    double huber_delta, PriorTerm prior) {
  check_problem(problem, state);
  const std::size_t lidars = state.T_base_lidar.size();
  const std::size_t pairs = state.T_world_base.size() * lidars;
  PairSums sums = reduce_rows(problem, state, pairs,
                              [huber_delta](const auto& c, const PairTransform& T, const MapMotion& motion, std::size_t pair, PairSums& s) {
                                const ResidualRows rows = rows_of(c, T, motion);
                                const double squared = rows.squared_norm();
                                const double weight = huber_weight(std::sqrt(squared), huber_delta);
                                for (std::size_t k = 0; k < static_cast<std::size_t>(rows.count); ++k) {
                                  s.H[pair].noalias() += (weight * rows.gradients[k]) * rows.gradients[k].transpose();
                                  s.g[pair].noalias() += weight * rows.values[k] * rows.gradients[k];
                                }
                                s.cost += 0.5 * huber_loss(squared, huber_delta);
                              });
  WindowLinearSystem system;
  system.H = Eigen::MatrixXd::Zero(layout.size, layout.size);
  system.g = Eigen::VectorXd::Zero(layout.size);
  system.cost = sums.cost;
  const int anchor_offset = problem.anchor.frame < 0 ? -1 : layout.pose_offset[static_cast<std::size_t>(problem.anchor.frame)];
  for (std::size_t pair = 0; pair < pairs; ++pair)
    scatter_pair(sums.H[pair], sums.g[pair], layout.pose_offset[pair / lidars], layout.extrinsic_offset[pair % lidars], anchor_offset,
                 system);
  if (prior == PriorTerm::kInclude) add_prior(problem.prior, state, layout, system);
  return system;
}

double window_cost(const WindowProblem& problem, const WindowState& state, double huber_delta) {
  check_problem(problem, state);
  const PairSums sums = reduce_rows(
      problem, state, 0, [huber_delta](const auto& c, const PairTransform& T, const MapMotion& motion, std::size_t, PairSums& s) {
        s.cost += 0.5 * huber_loss(squared_norm_of(c, T, motion), huber_delta);
      });
  double cost = sums.cost;
  if (!problem.prior.variables.empty()) cost += 0.5 * prior_residual(problem.prior, state).squaredNorm();
  return cost;
}

Eigen::VectorXd prior_residual(const LinearPrior& prior, const WindowState& state) {
  Eigen::VectorXd dx(static_cast<Eigen::Index>(6 * prior.variables.size()));
  for (std::size_t k = 0; k < prior.variables.size(); ++k)
    dx.segment<6>(static_cast<Eigen::Index>(6 * k)) = (state.value(prior.variables[k]) * prior.linearization_points[k].inverse()).log();
  return prior.residual + prior.jacobian * dx;
}

}  // namespace mlidar::slam
