#include "mlidar/calib/planes_refine.hpp"

#include <cmath>

#include <Eigen/Cholesky>

namespace mlidar::calib {
namespace {

constexpr int kParams = 15;
using Vec15 = Eigen::Matrix<double, kParams, 1>;
using Mat15 = Eigen::Matrix<double, kParams, kParams>;

struct State {
  SE3 T;
  std::array<Plane, 3> planes;
};

/// Normal equations of the Huber-weighted problem at a state (IRLS).
struct Linearization {
  Mat15 information = Mat15::Zero();  ///< J^T W J
  Mat15 curvature = Mat15::Zero();    ///< sum psi'(r) J J^T (Huber: J J^T over |r| <= delta)
  Mat15 score = Mat15::Zero();        ///< sum psi(r)^2 J J^T
  Vec15 gradient = Vec15::Zero();     ///< J^T W r
  double cost = 0.0;                  ///< sum rho(r)
  double weighted_sq = 0.0;           ///< sum w r^2
  std::size_t residuals = 0;
};

/// Orthonormal basis of the tangent plane of the unit sphere at n.
Eigen::Matrix<double, 3, 2> tangent_basis(const Vec3& n) {
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = n.unitOrthogonal();
  basis.col(1) = n.cross(basis.col(0));
  return basis;
}

double huber_weight(double r, double delta) { return std::abs(r) <= delta ? 1.0 : delta / std::abs(r); }
double huber_cost(double r, double delta) {
  const double a = std::abs(r);
  return a <= delta ? 0.5 * r * r : delta * (a - 0.5 * delta);
}

void accumulate(Linearization& lin, const Vec15& jacobian, double r, double delta) {
  const double w = huber_weight(r, delta);
  lin.information.selfadjointView<Eigen::Lower>().rankUpdate(jacobian, w);
  if (w == 1.0) lin.curvature.selfadjointView<Eigen::Lower>().rankUpdate(jacobian, 1.0);
  lin.score.selfadjointView<Eigen::Lower>().rankUpdate(jacobian, w * w * r * r);
  lin.gradient.noalias() += w * r * jacobian;
  lin.cost += huber_cost(r, delta);
  lin.weighted_sq += w * r * r;
  ++lin.residuals;
}

Linearization linearize(const RefineProblem& problem, const State& state, double delta) {
  Linearization lin;
  const Mat3 R = state.T.rotation_matrix();
  const Vec3& t = state.T.translation();
  for (int i = 0; i < 3; ++i) {
    const Plane& plane = state.planes[i];
    const Eigen::Matrix<double, 3, 2> basis = tangent_basis(plane.normal);
    const int block = 6 + 3 * i;
    Vec15 jacobian = Vec15::Zero();
    jacobian(block + 2) = 1.0;
    for (const Vec3& p : problem.ref_points[i]) {  // r = n.p + d
      jacobian.segment<2>(block) = basis.transpose() * p;
      accumulate(lin, jacobian, plane.signed_distance(p), delta);
    }
    const Vec3 rotated_normal = R.transpose() * plane.normal;
    jacobian.head<3>() = plane.normal;                // dr/d(dt)
    for (const Vec3& q : problem.target_points[i]) {  // r = n.(R q + t) + d
      const Vec3 x = R * q + t;
      jacobian.segment<3>(3) = q.cross(rotated_normal);  // dr/d(dr) = -n^T R [q]x
      jacobian.segment<2>(block) = basis.transpose() * x;
      accumulate(lin, jacobian, plane.signed_distance(x), delta);
    }
  }
  lin.information = lin.information.selfadjointView<Eigen::Lower>();
  lin.curvature = lin.curvature.selfadjointView<Eigen::Lower>();
  lin.score = lin.score.selfadjointView<Eigen::Lower>();
  return lin;
}

State retract(const State& state, const Vec15& step) {
  State next;
  next.T = SE3(state.T.rotation() * so3_exp(step.segment<3>(3)), state.T.translation() + step.head<3>());
  for (int i = 0; i < 3; ++i) {
    const Plane& plane = state.planes[i];
    const Vec3 moved = plane.normal + tangent_basis(plane.normal) * step.segment<2>(6 + 3 * i);
    next.planes[i] = {moved.normalized(), plane.offset + step(8 + 3 * i)};
  }
  return next;
}

double rms(const std::vector<Vec3>& points, const Plane& plane, const SE3& T) {
  double sum = 0.0;
  for (const Vec3& p : points) sum += std::pow(plane.signed_distance(T * p), 2);
  return points.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(points.size()));
}

}  // namespace

RefineResult refine_planes(const RefineProblem& problem, const RefineOptions& options) {
  State state{problem.T_ref_target, problem.planes_ref};
  Linearization lin = linearize(problem, state, options.huber_delta);
  double lambda = 1e-4;
  RefineResult result;
  for (result.iterations = 0; result.iterations < options.max_iterations; ++result.iterations) {
    Mat15 damped = lin.information;
    damped.diagonal() *= 1.0 + lambda;
    const Vec15 step = damped.ldlt().solve(-lin.gradient);
    const State candidate = retract(state, step);
    Linearization next = linearize(problem, candidate, options.huber_delta);
    if (next.cost < lin.cost) {  // LM: accept and trust the quadratic model more
      const double decrease = lin.cost - next.cost;
      state = candidate;
      lin = std::move(next);
      lambda = std::max(lambda * 0.1, 1e-12);
      if (step.norm() < 1e-10 || decrease <= 1e-12 * lin.cost) {
        result.converged = true;
        break;
      }
    } else {
      lambda *= 10.0;
      if (step.norm() < 1e-12 || lambda > 1e12) {
        result.converged = true;
        break;
      }
    }
  }
  result.T_ref_target = state.T;
  result.planes_ref = state.planes;
  const double m = static_cast<double>(lin.residuals);
  const double dof_scale = m / std::max(1.0, m - kParams);
  result.residual_sigma = std::sqrt(lin.weighted_sq / std::max(1.0, m - kParams));
  // Covariance of the M-estimate from the final normal equations (Huber 1981,
  // sec 7.6): A^-1 B A^-1 with A = sum psi'(r) J J^T, B = sum psi(r)^2 J J^T,
  // i.e. the residual variance scales the inverse information; without
  // down-weighted residuals it is s^2 (J^T J)^-1. The T block of the inverse
  // is the marginal over the planes.
  const Mat15 a_inverse = lin.curvature.ldlt().solve(Mat15::Identity());
  const Mat15 covariance = dof_scale * a_inverse * lin.score * a_inverse;
  result.covariance = 0.5 * (covariance.topLeftCorner<6, 6>() + covariance.topLeftCorner<6, 6>().transpose());
  for (int i = 0; i < 3; ++i) {
    result.rms_ref[i] = rms(problem.ref_points[i], state.planes[i], SE3());
    result.rms_target[i] = rms(problem.target_points[i], state.planes[i], state.T);
  }
  return result;
}

}  // namespace mlidar::calib
