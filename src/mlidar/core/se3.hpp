#pragma once
// Rigid transform T_a_b: p_a = R p_b + t. Tangent vectors are 6-vectors
// ordered [translation rho, rotation phi] everywhere in mlidar.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mlidar/core/so3.hpp"

namespace mlidar {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat4 = Eigen::Matrix4d;

class SE3 {
 public:
  SE3() = default;
  SE3(const Quat& rotation, const Vec3& translation);
  static SE3 identity() { return {}; }
  /// From a 4x4 homogeneous matrix; the rotation block is re-orthonormalised.
  static SE3 from_matrix(const Mat4& matrix);

  const Quat& rotation() const { return rotation_; }
  Mat3 rotation_matrix() const { return rotation_.toRotationMatrix(); }
  const Vec3& translation() const { return translation_; }
  Mat4 matrix() const;

  SE3 inverse() const;
  SE3 operator*(const SE3& other) const;
  Vec3 operator*(const Vec3& point) const { return rotation_ * point + translation_; }
  Eigen::Vector3f operator*(const Eigen::Vector3f& point) const {
    return (rotation_ * point.cast<double>() + translation_).cast<float>();
  }

  /// Exp of [rho, phi]: (Exp(phi), J_l(phi) rho).
  static SE3 exp(const Vec6& xi);
  /// Log, inverse of exp.
  Vec6 log() const;
  /// Adjoint: Ad(T) xi = log(T exp(xi) T^-1) to first order, for xi = [rho, phi].
  Mat6 adjoint() const;

 private:
  Quat rotation_ = Quat::Identity();
  Vec3 translation_ = Vec3::Zero();
};

}  // namespace mlidar
