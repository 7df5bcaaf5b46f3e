#include "mlidar/core/so3.hpp"

#include <cmath>

namespace mlidar {
namespace {
constexpr double kSmallAngle = 1e-6;
}

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
    // theta ~= 2 |v| / w; series keeps second-order accuracy.
    return (2.0 / q.w() - (2.0 / 3.0) * imag_norm * imag_norm / (q.w() * q.w() * q.w())) * imag;
  }
  // atan2 is well conditioned at both ends (theta -> 0 and theta -> pi).
  const double theta = 2.0 * std::atan2(imag_norm, q.w());
  return (theta / imag_norm) * imag;
}

Mat3 so3_left_jacobian(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 phi_hat = hat(phi);
  if (theta < kSmallAngle) {
    return Mat3::Identity() + 0.5 * phi_hat + (1.0 / 6.0) * phi_hat * phi_hat;
  }
  const double theta_sq = theta * theta;
  return Mat3::Identity() + ((1.0 - std::cos(theta)) / theta_sq) * phi_hat +
         ((theta - std::sin(theta)) / (theta_sq * theta)) * phi_hat * phi_hat;
}

Mat3 so3_left_jacobian_inverse(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 phi_hat = hat(phi);
  if (theta < kSmallAngle) {
    return Mat3::Identity() - 0.5 * phi_hat + (1.0 / 12.0) * phi_hat * phi_hat;
  }
  const double half = 0.5 * theta;
  const double cot_half = std::cos(half) / std::sin(half);
  const double coeff = (1.0 - half * cot_half) / (theta * theta);
  return Mat3::Identity() - 0.5 * phi_hat + coeff * phi_hat * phi_hat;
}

Mat3 so3_right_jacobian(const Vec3& phi) { return so3_left_jacobian(-phi); }
Mat3 so3_right_jacobian_inverse(const Vec3& phi) { return so3_left_jacobian_inverse(-phi); }

}  // namespace mlidar
