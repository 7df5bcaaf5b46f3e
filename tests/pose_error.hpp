#pragma once
// The tests' one measure of how far a pose is from another: the geodesic
// angle of the relative rotation, |Log(R_a^-1 R_b)|, and the distance of the
// translations, |t_a - t_b|.
#include "mlidar/core/conversions.hpp"
#include "mlidar/core/se3.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::test {

/// Angle of the rotation between a and b (rad), in [0, pi].
inline double rotation_error_rad(const Quat& a, const Quat& b) { return so3_log(a.conjugate() * b).norm(); }
inline double rotation_error_rad(const SE3& a, const SE3& b) { return rotation_error_rad(a.rotation(), b.rotation()); }
/// The same in degrees.
inline double rotation_error_deg(const SE3& a, const SE3& b) { return rad_to_deg(rotation_error_rad(a, b)); }
/// Distance between the translations (m).
inline double translation_error_m(const SE3& a, const SE3& b) { return (a.translation() - b.translation()).norm(); }
/// Angle (deg) of the rotation of one transform, e.g. an error truth^-1 * estimate: rotation_error_deg(identity, T).
inline double rotation_angle_deg(const SE3& T) { return rad_to_deg(so3_log(T.rotation()).norm()); }

}  // namespace mlidar::test
