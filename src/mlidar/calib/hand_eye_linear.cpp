#include "mlidar/calib/hand_eye_linear.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/SVD>

#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

Quat from_wxyz(const Eigen::Vector4d& v) { return Quat(v(0), v(1), v(2), v(3)).normalized(); }
Quat with_nonnegative_w(const Quat& q) { return q.w() < 0.0 ? Quat(-q.w(), -q.x(), -q.y(), -q.z()) : q; }

Mat4x quaternion_matrix(const Quat& q, double cross_sign) {
  const Vec3 v(q.x(), q.y(), q.z());
  Mat4x m;
  m(0, 0) = q.w();
  m.block<1, 3>(0, 1) = -v.transpose();
  m.block<3, 1>(1, 0) = v;
  m.block<3, 3>(1, 1) = q.w() * Mat3::Identity() + cross_sign * hat(v);
  return m;
}

/// Eq 3.9: the unit q = l1 v3 + l2 v4 with x y + z w = 0 (no yaw about z'),
/// a quadratic form in (l1, l2) = (cos s, sin s).
Quat pitch_roll_from_null_space(const Eigen::Vector4d& v3, const Eigen::Vector4d& v4) {
  const auto form = [](const Eigen::Vector4d& p, const Eigen::Vector4d& q) {
    return 0.5 * (p(1) * q(2) + p(2) * q(1) + p(3) * q(0) + p(0) * q(3));
  };
  const double m11 = form(v3, v3), m12 = form(v3, v4), m22 = form(v4, v4);
  // m11 c^2 + 2 m12 c s + m22 s^2 = 0: u = tan s solves m22 u^2 + 2 m12 u + m11 = 0. Either root is valid: they differ by a yaw of pi,
  // which eq 3.12 absorbs.
  double s_angle = std::numbers::pi / 2.0;  // c = 0 solves it when m22 = 0
  if (std::abs(m22) > 1e-15) {
    const double disc = std::max(0.0, m12 * m12 - m11 * m22);
    s_angle = std::atan((-m12 + std::sqrt(disc)) / m22);
  }
  return from_wxyz(std::cos(s_angle) * v3 + std::sin(s_angle) * v4);
}

}  // namespace

Mat4x quaternion_left_matrix(const Quat& q) { return quaternion_matrix(q, 1.0); }
Mat4x quaternion_right_matrix(const Quat& q) { return quaternion_matrix(q, -1.0); }

QuaternionSystem quaternion_system(std::span<const MotionPair> pairs, std::span<const double> weights) {
  assert(weights.empty() || weights.size() == pairs.size());
  Eigen::MatrixXd Q(4 * pairs.size(), 4);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const double w = weights.empty() ? 1.0 : weights[k];
    Q.block<4, 4>(4 * k, 0) = w * (quaternion_left_matrix(with_nonnegative_w(pairs[k].A.rotation())) -
                                   quaternion_right_matrix(with_nonnegative_w(pairs[k].B.rotation())));
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Q, Eigen::ComputeFullV);
  return {svd.matrixV(), svd.singularValues()};
}

Vec3 translation_least_squares(std::span<const MotionPair> pairs, const Quat& R_a_b) {
  Mat3 normal = Mat3::Zero();
  Vec3 rhs = Vec3::Zero();
  for (const MotionPair& pair : pairs) {
    const Mat3 M = pair.A.rotation_matrix() - Mat3::Identity();
    const Vec3 b = R_a_b * pair.B.translation() - pair.A.translation();
    normal += M.transpose() * M;
    rhs += M.transpose() * b;
  }
  return Eigen::JacobiSVD<Mat3>(normal, Eigen::ComputeFullU | Eigen::ComputeFullV).solve(rhs);
}

Vec3 common_rotation_axis(std::span<const MotionPair> pairs) {
  Vec3 reference = Vec3::Zero();
  for (const MotionPair& p : pairs) {
    const Vec3 phi = so3_log(p.A.rotation());
    if (phi.norm() > reference.norm()) reference = phi;
  }
  Vec3 sum = Vec3::Zero();
  for (const MotionPair& p : pairs) {
    const Vec3 phi = so3_log(p.A.rotation());
    sum += phi.dot(reference) >= 0.0 ? phi : Vec3(-phi);
  }
  return sum.norm() > 0.0 ? Vec3(sum.normalized()) : Vec3::UnitZ();
}

PlanarSolution solve_planar(std::span<const MotionPair> pairs, const Vec3& axis_a) {
  // Frame a' with z' = axis_a: A' = C A C^-1 and X' = C X.
  const SE3 C(Quat::FromTwoVectors(axis_a.normalized(), Vec3::UnitZ()), Vec3::Zero());
  std::vector<MotionPair> level;
  level.reserve(pairs.size());
  for (const MotionPair& pair : pairs) level.push_back({C * pair.A * C.inverse(), pair.B});

  const QuaternionSystem system = quaternion_system(level);
  const Quat q_yx = pitch_roll_from_null_space(system.V.col(2), system.V.col(3));  // eq 3.8-3.9

  // Eq 3.10-3.12: [R1, -J] [tx, ty, cos g, sin g]^T = -t2 per pair.
  Eigen::MatrixXd G(2 * level.size(), 4);
  Eigen::VectorXd rhs(2 * level.size());
  for (std::size_t k = 0; k < level.size(); ++k) {
    const Mat3 R1 = level[k].A.rotation_matrix() - Mat3::Identity();
    const Vec3 t1 = q_yx * level[k].B.translation();
    Eigen::Matrix2d J;
    J << t1.x(), -t1.y(), t1.y(), t1.x();
    G.block<2, 2>(2 * k, 0) = R1.topLeftCorner<2, 2>();
    G.block<2, 2>(2 * k, 2) = -J;
    rhs.segment<2>(2 * k) = -level[k].A.translation().head<2>();
  }
  const Eigen::Vector4d scale = G.colwise().norm().transpose().cwiseMax(1e-300);
  const Eigen::MatrixXd G_scaled = G * scale.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(G_scaled, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::Vector4d x = scale.cwiseInverse().asDiagonal() * svd.solve(rhs);
  const double yaw = std::atan2(x(3), x(2));
  const Quat q_level = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ())) * q_yx;
  const SE3 X_level(q_level.normalized(), Vec3(x(0), x(1), 0.0));
  const Eigen::Vector4d s = svd.singularValues();
  return {C.inverse() * X_level, s(0) > 0.0 ? s(3) / s(0) : 0.0};
}

}  // namespace mlidar::calib
