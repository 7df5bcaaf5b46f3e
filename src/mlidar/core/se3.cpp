#include "mlidar/core/se3.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/SVD>

#include "mlidar/core/error.hpp"

namespace mlidar {
namespace {
constexpr double kSeriesAngle = 1e-2;  // see so3.cpp

[[noreturn]] void reject_matrix(const std::string& problem) { throw InputError("", "4x4 matrix", problem); }

// Barfoot eq 7.86b: the coupling block Q(rho, phi) of the SE(3) left Jacobian.
Mat3 q_block(const Vec3& rho, const Vec3& phi) {
  const double t2 = phi.squaredNorm();
  const double t = std::sqrt(t2);
  double c1 = 0.0;  // (t - sin t) / t^3
  double c2 = 0.0;  // (t^2 + 2 cos t - 2) / (2 t^4)
  double c3 = 0.0;  // (2 t - 3 sin t + t cos t) / (2 t^5)
  if (t < kSeriesAngle) {
    // Taylor series; the closed forms cancel badly for small t.
    c1 = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
    c2 = 1.0 / 24.0 - t2 / 720.0 + t2 * t2 / 40320.0;
    c3 = 1.0 / 120.0 - t2 / 2520.0 + t2 * t2 / 120960.0;
  } else {
    const double s = std::sin(t);
    const double c = std::cos(t);
    const double t4 = t2 * t2;
    c1 = (t - s) / (t2 * t);
    // t^2 + 2 cos t - 2 = t^2 - 4 sin^2(t/2), factored to avoid cancellation.
    const double two_sin_half = 2.0 * std::sin(0.5 * t);
    c2 = (t - two_sin_half) * (t + two_sin_half) / (2.0 * t4);
    c3 = (2.0 * t - 3.0 * s + t * c) / (2.0 * t4 * t);
  }
  const Mat3 p = hat(phi);
  const Mat3 r = hat(rho);
  const Mat3 pr = p * r;
  const Mat3 rp = r * p;
  const Mat3 prp = pr * p;
  return 0.5 * r + c1 * (pr + rp + prp) + c2 * (p * pr + rp * p - 3.0 * prp) + c3 * (prp * p + p * prp);
}
// A quaternion already unit to rounding is kept as it is: normalising it again
// can move its last bit, so a pose written exactly and read back would not
// come back bit for bit (found by fuzz_dataset: format, parse, format differed).
Quat unit(const Quat& rotation) {
  constexpr double kRounding = 8.0 * std::numeric_limits<double>::epsilon();
  return std::abs(rotation.squaredNorm() - 1.0) <= kRounding ? rotation : rotation.normalized();
}

}  // namespace

SE3::SE3(const Quat& rotation, const Vec3& translation) : rotation_(unit(rotation)), translation_(translation) {}

SE3 SE3::from_matrix(const Mat4& matrix, double orthonormal_tolerance) {
  if (!matrix.allFinite()) reject_matrix("has a NaN or infinite entry (expected finite numbers)");
  const Eigen::RowVector4d bottom_error = matrix.bottomRows<1>() - Eigen::RowVector4d(0, 0, 0, 1);
  if (bottom_error.cwiseAbs().maxCoeff() > 1e-9) {
    reject_matrix("bottom row is not [0 0 0 1] (expected a homogeneous rigid transform)");
  }
  const Mat3 r = matrix.topLeftCorner<3, 3>();
  const double drift = (r.transpose() * r - Mat3::Identity()).norm();
  if (!(drift <= orthonormal_tolerance)) {
    reject_matrix("rotation block is not orthonormal, ||R^T R - I|| = " + std::to_string(drift) +
                  " (expected a rotation: no scale or shear)");
  }
  if (r.determinant() < 0.0) reject_matrix("rotation block has det < 0 (a reflection, expected a rotation)");
  // Nearest rotation in Frobenius norm: U V^T (det > 0 is guaranteed by the checks above).
  const Eigen::JacobiSVD<Mat3> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Mat3 r_ortho = svd.matrixU() * svd.matrixV().transpose();
  return {Quat(r_ortho), matrix.topRightCorner<3, 1>()};
}

Mat4 SE3::matrix() const {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = rotation_matrix();
  m.topRightCorner<3, 1>() = translation_;
  return m;
}

SE3 SE3::inverse() const {
  const Quat r_inv = rotation_.conjugate();
  return {r_inv, -(r_inv * translation_)};
}

SE3 SE3::operator*(const SE3& other) const { return {rotation_ * other.rotation_, rotation_ * other.translation_ + translation_}; }

SE3 SE3::exp(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  return {so3_exp(phi), so3_left_jacobian(phi) * rho};
}

Vec6 SE3::log() const {
  const Vec3 phi = so3_log(rotation_);
  Vec6 xi;
  xi.head<3>() = so3_left_jacobian_inverse(phi) * translation_;
  xi.tail<3>() = phi;
  return xi;
}

Mat6 SE3::adjoint() const {
  const Mat3 r = rotation_matrix();
  Mat6 ad = Mat6::Zero();
  ad.topLeftCorner<3, 3>() = r;
  ad.topRightCorner<3, 3>() = hat(translation_) * r;
  ad.bottomRightCorner<3, 3>() = r;
  return ad;
}

SE3 interpolate(const SE3& a, const SE3& b, double s) { return a * SE3::exp(s * (a.inverse() * b).log()); }

void transform_points(const SE3& T, std::span<const Eigen::Vector3f> points, std::span<Eigen::Vector3f> out) {
  if (points.size() != out.size()) {
    throw std::invalid_argument("transform_points: " + std::to_string(points.size()) + " points but room for " +
                                std::to_string(out.size()) + " (expected equal sizes)");
  }
  const Mat3 r = T.rotation_matrix();
  const Vec3& t = T.translation();
  for (std::size_t i = 0; i < points.size(); ++i) out[i] = (r * points[i].cast<double>() + t).cast<float>();
}

Mat6 se3_left_jacobian(const Vec6& xi) {
  const Vec3 phi = xi.tail<3>();
  const Mat3 j = so3_left_jacobian(phi);
  Mat6 out = Mat6::Zero();
  out.topLeftCorner<3, 3>() = j;
  out.topRightCorner<3, 3>() = q_block(xi.head<3>(), phi);
  out.bottomRightCorner<3, 3>() = j;
  return out;
}

Mat6 se3_left_jacobian_inverse(const Vec6& xi) {
  const Vec3 phi = xi.tail<3>();
  const Mat3 j_inv = so3_left_jacobian_inverse(phi);
  Mat6 out = Mat6::Zero();
  out.topLeftCorner<3, 3>() = j_inv;
  out.topRightCorner<3, 3>() = -j_inv * q_block(xi.head<3>(), phi) * j_inv;
  out.bottomRightCorner<3, 3>() = j_inv;
  return out;
}

Mat6 se3_right_jacobian(const Vec6& xi) { return se3_left_jacobian(-xi); }
Mat6 se3_right_jacobian_inverse(const Vec6& xi) { return se3_left_jacobian_inverse(-xi); }

}  // namespace mlidar
