#pragma once
// Conversions between rotation / pose representations used in files and configs.
// Angles are in radians unless a name ends in _deg.
#include <numbers>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"

namespace mlidar {

using Vec4 = Eigen::Vector4d;

constexpr double deg_to_rad(double deg) { return deg * (std::numbers::pi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / std::numbers::pi); }

/// Quaternion from [w, x, y, z] (the order of our YAML files), normalised.
/// Throws InputError (field "quaternion_wxyz") when an entry is not finite or
/// the norm is below 1e-6 (not a rotation).
Quat quat_from_wxyz(const Vec4& wxyz);
/// [w, x, y, z] with w >= 0 (q and -q are the same rotation).
Vec4 quat_to_wxyz(const Quat& q);

/// Rotation vector (axis * angle) <-> quaternion: so3_exp / so3_log by name.
inline Quat quat_from_rotation_vector(const Vec3& rotation_vector) { return so3_exp(rotation_vector); }
inline Vec3 rotation_vector_from_quat(const Quat& q) { return so3_log(q); }

/// Thesis convention: R = Rz(yaw) * Ry(pitch) * Rx(roll) (extrinsic x-y-z,
/// i.e. intrinsic z-y'-x''); rpy = [roll, pitch, yaw].
Quat quat_from_rpy(const Vec3& rpy);
/// Inverse of quat_from_rpy with roll, yaw in [-pi, pi], pitch in [-pi/2, pi/2].
/// Near gimbal lock (|pitch| -> pi/2) only roll -+ yaw is well defined; roll is
/// solved from the residual Ry(pitch)^T Rz(yaw)^T R so quat_from_rpy(result)
/// still reproduces q (to ~1e-13 rad). Within 1e-14 rad of the lock roll is 0
/// and yaw takes the whole angle.
Vec3 rpy_from_quat(const Quat& q);
/// Same in degrees.
Quat quat_from_rpy_deg(const Vec3& rpy_deg);
Vec3 rpy_deg_from_quat(const Quat& q);

/// 4x4 homogeneous matrix <-> SE3 (SE3::from_matrix documents what it fixes
/// and what it rejects).
inline SE3 se3_from_matrix(const Mat4& matrix) { return SE3::from_matrix(matrix); }
inline Mat4 se3_to_matrix(const SE3& pose) { return pose.matrix(); }

}  // namespace mlidar
