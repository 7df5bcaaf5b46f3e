#pragma once
// Rigid transform T_a_b: p_a = R p_b + t. Tangent vectors are 6-vectors
// ordered [translation rho, rotation phi] everywhere in mlidar; this is also
// Barfoot's order (State Estimation for Robotics, sec 7.1), xi^ = [phi^ rho; 0 0].
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mlidar/core/so3.hpp"

namespace mlidar {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat4 = Eigen::Matrix4d;

class SE3 {
 public:
  /// Largest accepted ||R^T R - I||_F (Frobenius) of the rotation block in from_matrix.
  static constexpr double kDefaultOrthonormalTolerance = 1e-3;

  SE3() = default;
  SE3(const Quat& rotation, const Vec3& translation);
  static SE3 identity() { return {}; }
  /// From a 4x4 homogeneous matrix [R t; 0 0 0 1].
  /// Fixes: R within `orthonormal_tolerance` of a rotation (e.g. rounded text)
  ///   is projected onto the nearest rotation (SVD, Frobenius-nearest).
  /// Rejects (throws InputError, field "4x4 matrix"): a non-finite entry, a
  ///   bottom row other than [0 0 0 1], ||R^T R - I||_F above the tolerance
  ///   (scale or shear), or det(R) < 0 (a reflection).
  static SE3 from_matrix(const Mat4& matrix, double orthonormal_tolerance = kDefaultOrthonormalTolerance);

  const Quat& rotation() const { return rotation_; }
  Mat3 rotation_matrix() const { return rotation_.toRotationMatrix(); }
  const Vec3& translation() const { return translation_; }
  Mat4 matrix() const;

  SE3 inverse() const;
  SE3 operator*(const SE3& other) const;
  Vec3 operator*(const Vec3& point) const { return rotation_ * point + translation_; }
  Eigen::Vector3f operator*(const Eigen::Vector3f& point) const { return (rotation_ * point.cast<double>() + translation_).cast<float>(); }

  /// Exp of [rho, phi]: (Exp(phi), J_l(phi) rho).
  static SE3 exp(const Vec6& xi);
  /// Log, inverse of exp; the rotation angle lies in [0, pi].
  Vec6 log() const;
  /// Adjoint [R, [t]x R; 0, R]: T exp(xi) T^-1 = exp(Ad(T) xi) for xi = [rho, phi].
  Mat6 adjoint() const;

 private:
  Quat rotation_ = Quat::Identity();
  Vec3 translation_ = Vec3::Zero();
};

/// Geodesic interpolation a * exp(s * log(a^-1 b)): s = 0 gives a, s = 1 gives b,
/// constant body twist in between (a constant-velocity motion); s outside
/// [0, 1] extrapolates.
SE3 interpolate(const SE3& a, const SE3& b, double s);

/// out[i] = T * points[i] for a whole cloud (float points, double pose); the
/// rotation matrix is built once, ~6x faster than calling operator* per point.
/// out may be the same memory as points. Throws std::invalid_argument when the
/// sizes differ.
void transform_points(const SE3& T, std::span<const Eigen::Vector3f> points, std::span<Eigen::Vector3f> out);

/// SE(3) left Jacobian, Barfoot eq 7.85a: [J_l(phi), Q(xi); 0, J_l(phi)], so that
/// exp(xi + d) ~= exp(J_l(xi) d) exp(xi).
Mat6 se3_left_jacobian(const Vec6& xi);
/// Its inverse, Barfoot eq 7.85b: [J^-1, -J^-1 Q J^-1; 0, J^-1].
Mat6 se3_left_jacobian_inverse(const Vec6& xi);
/// Right Jacobian J_r(xi) = J_l(-xi): exp(xi + d) ~= exp(xi) exp(J_r(xi) d).
Mat6 se3_right_jacobian(const Vec6& xi);
Mat6 se3_right_jacobian_inverse(const Vec6& xi);

}  // namespace mlidar
