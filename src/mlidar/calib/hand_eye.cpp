#include "mlidar/calib/hand_eye.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "mlidar/calib/hand_eye_linear.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

void validate(const HandEyeConfig& c) {
  const bool ok = c.screw_angle_tolerance_rad > 0 && c.screw_pitch_tolerance_m > 0 && c.min_axis_angle_rad > 0 && c.min_pairs >= 2 &&
                  c.min_rotation_rad >= 0 && c.planar_singular_ratio > 0 && c.planar_singular_ratio < 1 && c.degenerate_condition > 0 &&
                  c.refine_iterations >= 0 && c.unobservable_variance > 0;
  if (!ok) throw std::invalid_argument("HandEyeConfig: a tolerance is out of range (all > 0, ratio < 1, min_pairs >= 2)");
}

struct Residuals {
  double rotation_sq = 0.0;
  double translation_sq = 0.0;
};

Residuals residuals(std::span<const MotionPair> pairs, const SE3& X) {
  Residuals r;
  for (const MotionPair& p : pairs) {
    const Vec3 e_r = so3_log(p.A.rotation()) - X.rotation() * so3_log(p.B.rotation());
    const Vec3 e_t = (p.A.rotation_matrix() - Mat3::Identity()) * X.translation() - X.rotation() * p.B.translation() + p.A.translation();
    r.rotation_sq += e_r.squaredNorm();
    r.translation_sq += e_t.squaredNorm();
  }
  return r;
}

/// Normal equations of the weighted residuals e_r = phi_A - R phi_B and
/// e_t = (R_A - I) t - R t_B + t_A (eq 3.2-3.3) in x = [t, d], X = (Exp(d) R, t):
/// de_r/dd = [R phi_B]x, de_t/dt = R_A - I, de_t/dd = [R t_B]x.
struct NormalEquations {
  Mat6 H = Mat6::Zero();
  Vec6 g = Vec6::Zero();
};

NormalEquations normal_equations(std::span<const MotionPair> pairs, const SE3& X, double w_r, double w_t) {
  NormalEquations n;
  for (const MotionPair& p : pairs) {
    const Vec3 Rphi = X.rotation() * so3_log(p.B.rotation());
    const Vec3 Rt = X.rotation() * p.B.translation();
    const Mat3 M = p.A.rotation_matrix() - Mat3::Identity();
    const Vec3 e_r = so3_log(p.A.rotation()) - Rphi;
    const Vec3 e_t = M * X.translation() - Rt + p.A.translation();
    Eigen::Matrix<double, 3, 6> J_r = Eigen::Matrix<double, 3, 6>::Zero();
    J_r.rightCols<3>() = hat(Rphi);
    Eigen::Matrix<double, 3, 6> J_t;
    J_t << M, hat(Rt);
    n.H += w_r * J_r.transpose() * J_r + w_t * J_t.transpose() * J_t;
    n.g += w_r * J_r.transpose() * e_r + w_t * J_t.transpose() * e_t;
  }
  return n;
}

/// Gauss-Newton on the joint residuals; under planar motion a prior holds the
/// translation along `axis` at its current value (it is unobservable there).
/// Returns the covariance H^-1 with residual-estimated weights.
Mat6 refine(std::span<const MotionPair> pairs, SE3& X, const HandEyeConfig& config, const Vec3* axis) {
  const double dof = std::max(1.0, 3.0 * static_cast<double>(pairs.size()) - 3.0);
  const auto weights = [&](const SE3& estimate) {
    const Residuals r = residuals(pairs, estimate);
    return std::pair{1.0 / std::max(r.rotation_sq / dof, 1e-24), 1.0 / std::max(r.translation_sq / dof, 1e-24)};
  };
  auto [w_r, w_t] = weights(X);
  Mat6 prior = Mat6::Zero();
  if (axis != nullptr) prior.topLeftCorner<3, 3>() = (*axis) * axis->transpose() / config.unobservable_variance;
  for (int it = 0; it < config.refine_iterations; ++it) {
    const NormalEquations n = normal_equations(pairs, X, w_r, w_t);
    const Vec6 step = (n.H + prior).ldlt().solve(-n.g);
    if (!step.allFinite()) break;
    X = SE3(so3_exp(step.tail<3>()) * X.rotation(), X.translation() + step.head<3>());
    if (step.norm() < 1e-12) break;
  }
  std::tie(w_r, w_t) = weights(X);
  const NormalEquations n = normal_equations(pairs, X, w_r, w_t);
  return (n.H + prior).inverse();
}

}  // namespace

std::string_view to_string(HandEyeVerdict verdict) {
  switch (verdict) {
    case HandEyeVerdict::ok:
      return "ok";
    case HandEyeVerdict::planar_motion:
      return "planar_motion";
    case HandEyeVerdict::degenerate_motion:
      return "degenerate_motion";
    case HandEyeVerdict::too_few_pairs:
      return "too_few_pairs";
  }
  return "unknown";
}

ScrewResidual screw_residual(const MotionPair& pair, const HandEyeConfig& config) {
  // Eq 3.4: the rotation angle and the screw pitch r.t are the same for A and B.
  const Vec3 phi_a = so3_log(pair.A.rotation()), phi_b = so3_log(pair.B.rotation());
  const double theta_a = phi_a.norm(), theta_b = phi_b.norm();
  ScrewResidual r;
  r.angle_rad = std::abs(theta_a - theta_b);
  if (std::min(theta_a, theta_b) < config.min_axis_angle_rad) {
    r.pitch_m = std::abs(pair.A.translation().norm() - pair.B.translation().norm());
  } else {
    r.pitch_m = std::abs(phi_a.dot(pair.A.translation()) / theta_a - phi_b.dot(pair.B.translation()) / theta_b);
  }
  r.inlier = r.angle_rad <= config.screw_angle_tolerance_rad && r.pitch_m <= config.screw_pitch_tolerance_m;
  return r;
}

HandEyeResult solve_hand_eye(std::span<const MotionPair> pairs, const HandEyeConfig& config) {
  validate(config);
  HandEyeResult result;
  std::vector<MotionPair> inliers;
  double largest_rotation = 0.0;
  for (const MotionPair& pair : pairs) {
    result.screw.push_back(screw_residual(pair, config));
    if (!result.screw.back().inlier) continue;
    inliers.push_back(pair);
    largest_rotation = std::max(largest_rotation, so3_log(pair.A.rotation()).norm());
  }
  result.pairs_used = inliers.size();
  result.pairs_rejected = pairs.size() - inliers.size();
  if (inliers.size() < config.min_pairs) {
    result.message = "fewer motion pairs than min_pairs passed the screw-motion filter (eq 3.4)";
    return result;
  }
  const QuaternionSystem system = quaternion_system(inliers);  // eq 3.5-3.7
  for (int i = 0; i < 4; ++i) result.singular_values[i] = system.singular(i);
  if (largest_rotation < config.min_rotation_rad) {
    result.verdict = HandEyeVerdict::degenerate_motion;
    result.message = "pure translation: no pair rotates by min_rotation_rad; the rotation is unobservable";
    return result;
  }
  const bool parallel_axes = system.singular(2) < config.planar_singular_ratio * system.singular(0);
  if (!parallel_axes) {
    SE3 X(Quat(system.V(0, 3), system.V(1, 3), system.V(2, 3), system.V(3, 3)).normalized(), Vec3::Zero());
    X = SE3(X.rotation(), translation_least_squares(inliers, X.rotation()));  // eq 3.3
    result.covariance = refine(inliers, X, config, nullptr);
    result.T_a_b = X;
    result.verdict = HandEyeVerdict::ok;
    result.message = "general motion: rotation and translation observable";
  } else {
    const Vec3 axis = common_rotation_axis(inliers);
    const PlanarSolution planar = solve_planar(inliers, axis);  // eq 3.8-3.12
    if (planar.condition < config.degenerate_condition) {
      result.verdict = HandEyeVerdict::degenerate_motion;
      result.message = "one rotation axis and too little translation across it: yaw or x, y unobservable";
      return result;
    }
    SE3 X = planar.T_a_b;
    result.covariance = refine(inliers, X, config, &axis);
    result.T_a_b = X;
    result.verdict = HandEyeVerdict::planar_motion;
    result.t_z_observable = false;
    result.planar_axis_a = axis;
    result.message = "planar motion: translation along the rotation axis unobservable (set to 0), use the ground planes";
  }
  const Residuals r = residuals(inliers, result.T_a_b);
  const double n = static_cast<double>(inliers.size());
  result.rotation_rms_rad = std::sqrt(r.rotation_sq / n);
  result.translation_rms_m = std::sqrt(r.translation_sq / n);
  return result;
}

}  // namespace mlidar::calib
