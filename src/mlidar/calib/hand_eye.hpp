#pragma once
// Motion-based extrinsic initialisation, AX = XB (thesis Sec. 3.4.2):
//   A_k = T_{a_{k-1} a_k}, the base LiDAR's own motion between two frames;
//   B_k = T_{b_{k-1} b_k}, the target LiDAR's own motion over the same frames;
//   X   = T_a_b (T_base_lidar), so A_k X = X B_k (eq 3.1).
// Stages: screw-motion filter (eq 3.4); rotation from the stacked quaternion
// system by SVD (eq 3.5-3.7); the planar case, detected from the singular
// values, solved as pitch/roll (eq 3.8-3.9) then yaw and x, y (eq 3.10-3.12),
// t_z left unobservable; otherwise the translation by least squares (eq 3.3)
// and a joint Gauss-Newton refinement. The covariance comes from the
// residual variances and the normal equations.
#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/core/se3.hpp"

namespace mlidar::calib {

struct MotionPair {
  SE3 A;  ///< T_{a_{k-1} a_k}
  SE3 B;  ///< T_{b_{k-1} b_k}
};

struct HandEyeConfig {
  double screw_angle_tolerance_rad = 0.01;  ///< eq 3.4 |theta_a - theta_b| above this rejects
  double screw_pitch_tolerance_m = 0.02;    ///< eq 3.4 |r_a.t_a - r_b.t_b| above this rejects
  double min_axis_angle_rad = 1e-3;         ///< below: axis undefined, compare |t| instead of r.t
  std::size_t min_pairs = 3;                ///< fewer inliers: too_few_pairs
  double min_rotation_rad = 0.01;           ///< largest inlier rotation below this: pure translation
  double planar_singular_ratio = 0.05;      ///< s3 / s1 below this: all rotation axes parallel
  double degenerate_condition = 1e-3;       ///< planar system's s_min / s_max below this: degenerate
  int refine_iterations = 10;               ///< Gauss-Newton steps after the linear solution
  double unobservable_variance = 1.0;       ///< variance reported for t_z under planar motion (m^2)
};

enum class HandEyeVerdict { ok, planar_motion, degenerate_motion, too_few_pairs };
std::string_view to_string(HandEyeVerdict verdict);

struct ScrewResidual {
  double angle_rad = 0.0;  ///< |theta_a - theta_b|
  double pitch_m = 0.0;    ///< |r_a.t_a - r_b.t_b| (or ||t_a| - |t_b|| for tiny rotations)
  bool inlier = false;
};

struct HandEyeResult {
  HandEyeVerdict verdict = HandEyeVerdict::too_few_pairs;
  SE3 T_a_b;                         ///< the estimate (identity when too_few_pairs / degenerate)
  Mat6 covariance = Mat6::Zero();    ///< [t, r], rotation as a left perturbation Exp(d) R
  std::vector<ScrewResidual> screw;  ///< one per input pair
  std::size_t pairs_used = 0;
  std::size_t pairs_rejected = 0;
  std::array<double, 4> singular_values{};  ///< eq 3.7 Q_N, descending
  bool t_z_observable = true;               ///< false under planar motion (eq 3.10 sets t_z = 0)
  Vec3 planar_axis_a = Vec3::UnitZ();       ///< common rotation axis in {a} (planar case)
  double rotation_rms_rad = 0.0;            ///< rms of phi_a - R phi_b over inliers
  double translation_rms_m = 0.0;           ///< rms of eq 3.3 residuals over inliers
  std::string message;                      ///< why the verdict, for people
};

/// Eq 3.4 residuals of one pair (independent of X).
ScrewResidual screw_residual(const MotionPair& pair, const HandEyeConfig& config);

/// Calibrates one target against the base. Throws std::invalid_argument for a
/// config out of range. The pairs' order does not change the result beyond rounding.
HandEyeResult solve_hand_eye(std::span<const MotionPair> pairs, const HandEyeConfig& config = {});

}  // namespace mlidar::calib
