#include "mlidar/core/conversions.hpp"

#include <cmath>

#include "mlidar/core/error.hpp"

namespace mlidar {
namespace {
// cos(pitch) below this counts as gimbal lock in rpy_from_quat.
constexpr double kGimbalLockCos = 1e-14;

Vec3 deg_to_rad(const Vec3& deg) { return deg * (std::numbers::pi / 180.0); }
}  // namespace

Quat quat_from_wxyz(const Vec4& wxyz) {
  if (!wxyz.allFinite()) {
    throw InputError("", "quaternion_wxyz", "has a NaN or infinite entry (expected 4 finite numbers)");
  }
  if (wxyz.norm() < 1e-6) {
    throw InputError("", "quaternion_wxyz", "has norm ~0 (expected a unit quaternion [w, x, y, z])");
  }
  return Quat(wxyz(0), wxyz(1), wxyz(2), wxyz(3)).normalized();
}

Vec4 quat_to_wxyz(const Quat& q) {
  const Quat unit = q.normalized();
  const double sign = unit.w() < 0.0 ? -1.0 : 1.0;
  return sign * Vec4(unit.w(), unit.x(), unit.y(), unit.z());
}

Quat quat_from_rpy(const Vec3& rpy) {
  return Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) * Eigen::AngleAxisd(rpy.x(), Vec3::UnitX());
}

// With R = Rz(y) Ry(p) Rx(r): R(2,0) = -sin p, R(0,0) = cos p cos y, R(1,0) = cos p sin y.
Vec3 rpy_from_quat(const Quat& q) {
  const Mat3 r = q.normalized().toRotationMatrix();
  const double cos_pitch = std::hypot(r(0, 0), r(1, 0));
  const double pitch = std::atan2(-r(2, 0), cos_pitch);
  // At the lock R(0,1) = -sin(y -+ r), R(1,1) = cos(y -+ r): give the angle to yaw.
  const double yaw = cos_pitch < kGimbalLockCos ? std::atan2(-r(0, 1), r(1, 1)) : std::atan2(r(1, 0), r(0, 0));
  // Roll from the residual Rx(roll) = Ry(p)^T Rz(y)^T R absorbs any yaw error
  // (near the lock a yaw error is almost a rotation about x).
  const Mat3 residual =
      Eigen::AngleAxisd(-pitch, Vec3::UnitY()).toRotationMatrix() * Eigen::AngleAxisd(-yaw, Vec3::UnitZ()).toRotationMatrix() * r;
  const double roll = std::atan2(residual(2, 1), residual(2, 2));
  return {roll, pitch, yaw};
}

Quat quat_from_rpy_deg(const Vec3& rpy_deg) { return quat_from_rpy(deg_to_rad(rpy_deg)); }

Vec3 rpy_deg_from_quat(const Quat& q) { return rpy_from_quat(q) * (180.0 / std::numbers::pi); }

}  // namespace mlidar
