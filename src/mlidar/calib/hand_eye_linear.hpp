#pragma once
// Linear building blocks of the hand-eye solver (hand_eye.hpp), exposed for tests.
#include <span>

#include <Eigen/Core>

#include "mlidar/calib/hand_eye.hpp"

namespace mlidar::calib {

using Mat4x = Eigen::Matrix4d;

/// Eq 3.6 with w first, q = [w, x, y, z]: q (x) p = left(q) p, p (x) q = right(q) p.
Mat4x quaternion_left_matrix(const Quat& q);
Mat4x quaternion_right_matrix(const Quat& q);

struct QuaternionSystem {
  Eigen::Matrix4d V;         ///< right singular vectors, columns in descending order
  Eigen::Vector4d singular;  ///< descending
};
/// Eq 3.5-3.7: SVD of the stacked [left(q_A) - right(q_B)] (4N x 4), both
/// quaternions taken with w >= 0 so that the blocks agree in sign. `weights`
/// is empty (all 1) or one row weight per pair (eq 4.16's w_k).
QuaternionSystem quaternion_system(std::span<const MotionPair> pairs, std::span<const double> weights = {});

/// Eq 3.3 stacked, rotation known: (R_A - I) t = R t_B - t_A by least squares.
Vec3 translation_least_squares(std::span<const MotionPair> pairs, const Quat& R_a_b);

/// Unit common rotation axis of the A's (the axis of eq 3.8-3.12): their
/// rotation vectors sign-aligned with the largest one, summed by angle; z when
/// none rotates.
Vec3 common_rotation_axis(std::span<const MotionPair> pairs);

struct PlanarSolution {
  SE3 T_a_b;               ///< component of t along the axis set to 0
  double condition = 0.0;  ///< s_min / s_max of the column-scaled eq 3.12 system
};
/// Planar motion (every rotation axis of A along `axis_a`): eq 3.8-3.12 in a
/// frame a' whose z is axis_a.
PlanarSolution solve_planar(std::span<const MotionPair> pairs, const Vec3& axis_a);

}  // namespace mlidar::calib
