#pragma once
// SO(3) helpers on Eigen types. Rotation vectors are axis * angle (rad).
// Conventions: Exp/Log are the matrix exponential/logarithm of the hat map;
// the left Jacobian J_l satisfies Exp(phi + d) ~= Exp(J_l(phi) d) Exp(phi),
// the right one Exp(phi + d) ~= Exp(phi) Exp(J_r(phi) d).
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mlidar {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

/// Skew-symmetric matrix [v]x so that hat(a) * b = a x b.
Mat3 hat(const Vec3& v);
/// Inverse of hat for a skew-symmetric matrix.
Vec3 vee(const Mat3& m);

/// Exp: rotation vector -> unit quaternion (Rodrigues, stable near zero).
Quat so3_exp(const Vec3& phi);
/// Log: unit quaternion -> rotation vector with angle in [0, pi] (stable near 0 and pi).
Vec3 so3_log(const Quat& q);
/// Geodesic interpolation a * Exp(s * Log(a^-1 b)) along the shorter arc;
/// s = 0 gives a, s = 1 gives b, s outside [0, 1] extrapolates.
Quat so3_slerp(const Quat& a, const Quat& b, double s);

/// Left Jacobian of SO(3) and its inverse (Barfoot, State Estimation, eq 7.77a/7.79).
Mat3 so3_left_jacobian(const Vec3& phi);
Mat3 so3_left_jacobian_inverse(const Vec3& phi);
/// Right Jacobian J_r(phi) = J_l(-phi), and its inverse.
Mat3 so3_right_jacobian(const Vec3& phi);
Mat3 so3_right_jacobian_inverse(const Vec3& phi);

}  // namespace mlidar
