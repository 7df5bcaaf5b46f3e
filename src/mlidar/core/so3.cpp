#include "mlidar/core/so3.hpp"

#include <cmath>

namespace mlidar {
namespace {
// Below this angle Exp/Log use their Taylor series (truncation error < 1e-27).
constexpr double kSmallAngle = 1e-6;
// Below this angle the Jacobian coefficients use Taylor series up to theta^4:
// the closed forms lose digits to cancellation there, the series' truncation
// error stays below 1e-16.
constexpr double kSeriesAngle = 1e-2;
}  // namespace

Mat3 hat(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return m;
}

Vec3 vee(const Mat3& m) { return {m(2, 1), m(0, 2), m(1, 0)}; }

Quat so3_exp(const Vec3& phi) {
  const double theta_sq = phi.squaredNorm();
  const double theta = std::sqrt(theta_sq);
  double real = 0.0;
  double imag_factor = 0.0;  // sin(theta/2) / theta
  if (theta < kSmallAngle) {
    real = 1.0 - theta_sq / 8.0;
    imag_factor = 0.5 - theta_sq / 48.0;
  } else {
    real = std::cos(0.5 * theta);
    imag_factor = std::sin(0.5 * theta) / theta;
  }
  Quat q(real, imag_factor * phi.x(), imag_factor * phi.y(), imag_factor * phi.z());
  q.normalize();
  return q;
}

Vec3 so3_log(const Quat& q_in) {
  Quat q = q_in.normalized();
  // q and -q are the same rotation: pick w >= 0 so the angle lies in [0, pi].
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Vec3 imag = q.vec();
  const double imag_norm = imag.norm();
  if (imag_norm < kSmallAngle) {
    // theta = 2 atan(|v| / w) ~= 2 |v| / w - (2/3) |v|^3 / w^3 (w ~= 1 here).
    return (2.0 / q.w() - (2.0 / 3.0) * imag_norm * imag_norm / (q.w() * q.w() * q.w())) * imag;
  }
  // atan2 is well conditioned at both ends (theta -> 0 and theta -> pi).
  const double theta = 2.0 * std::atan2(imag_norm, q.w());
  return (theta / imag_norm) * imag;
}

Quat so3_slerp(const Quat& a, const Quat& b, double s) {
  const Quat a_unit = a.normalized();
  const Vec3 delta = so3_log(a_unit.conjugate() * b.normalized());
  return (a_unit * so3_exp(s * delta)).normalized();
}

// Barfoot eq 7.77a: J_l = I + (1 - cos t)/t^2 [phi]x + (t - sin t)/t^3 [phi]x^2.
Mat3 so3_left_jacobian(const Vec3& phi) {
  const double theta_sq = phi.squaredNorm();
  const double theta = std::sqrt(theta_sq);
  double c1 = 0.0;  // (1 - cos t) / t^2
  double c2 = 0.0;  // (t - sin t) / t^3
  if (theta < kSeriesAngle) {
    c1 = 0.5 - theta_sq / 24.0 + theta_sq * theta_sq / 720.0;
    c2 = 1.0 / 6.0 - theta_sq / 120.0 + theta_sq * theta_sq / 5040.0;
  } else {
    const double sin_half = std::sin(0.5 * theta);
    c1 = 2.0 * sin_half * sin_half / theta_sq;  // 1 - cos t = 2 sin^2(t/2), no cancellation
    c2 = (theta - std::sin(theta)) / (theta_sq * theta);
  }
  const Mat3 phi_hat = hat(phi);
  return Mat3::Identity() + c1 * phi_hat + c2 * phi_hat * phi_hat;
}

// Barfoot eq 7.79: J_l^-1 = I - 1/2 [phi]x + (1 - (t/2) cot(t/2))/t^2 [phi]x^2.
// Singular only at t = 2 pi, outside the range of so3_log.
Mat3 so3_left_jacobian_inverse(const Vec3& phi) {
  const double theta_sq = phi.squaredNorm();
  const double theta = std::sqrt(theta_sq);
  double c2 = 0.0;  // (1 - (t/2) cot(t/2)) / t^2
  if (theta < kSeriesAngle) {
    c2 = 1.0 / 12.0 + theta_sq / 720.0 + theta_sq * theta_sq / 30240.0;
  } else {
    const double half = 0.5 * theta;
    c2 = (1.0 - half * std::cos(half) / std::sin(half)) / theta_sq;
  }
  const Mat3 phi_hat = hat(phi);
  return Mat3::Identity() - 0.5 * phi_hat + c2 * phi_hat * phi_hat;
}

Mat3 so3_right_jacobian(const Vec3& phi) { return so3_left_jacobian(-phi); }
Mat3 so3_right_jacobian_inverse(const Vec3& phi) { return so3_left_jacobian_inverse(-phi); }

}  // namespace mlidar
