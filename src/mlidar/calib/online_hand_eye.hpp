#pragma once
// Online extrinsic initialisation of one auxiliary LiDAR (thesis Sec. 4.6.2,
// eq 4.13-4.18), one motion pair at a time:
//   A_k = T_{b_{k-1} b_k}, the base's motion between consecutive frames;
//   B_k = T_{l_{k-1} l_k}, the LiDAR's own motion over the same frames;
//   X   = T_base_lidar, so A_k X = X B_k (the convention of hand_eye.hpp).
// Rotation: the stacked, Huber-weighted quaternion system Q_K q = 0 (eq
// 4.15-4.16) solved by SVD; it is observable once the second-smallest
// singular value exceeds sigma_R (eq 4.17's test). Translation: eq 4.18 by
// least squares; when the base's rotation axes are (nearly) all parallel
// (planar motion) the translation along that axis is unobservable and is
// fixed to 0 (t_z = 0 for a ground robot) with planar_motion set. A pair may
// be given for its rotation only (its translations inconsistent, eq 3.4's
// pitch); the translation is ready only from translation_min_pairs such pairs
// and a predicted standard deviation below translation_max_std_m. With
// planar_rotation, rotations about one common axis start from eq 3.8-3.12.
// The state is recomputed from the stored pairs on every add.
#include <array>
#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

#include "mlidar/calib/hand_eye.hpp"

namespace mlidar::calib {

struct OnlineHandEyeConfig {
  std::size_t max_constraints = 300;  ///< K: pairs kept; when full the smallest rotation is dropped
  double rotation_threshold = 0.25;   ///< sigma_R: rotation ready when sigma_min2(Q_K) exceeds it
  double huber_delta_rad = 0.0873;    ///< eq 4.17: rows whose residual angle exceeds it get weight delta / phi (5 deg)
  /// Planar when lambda_min / lambda_max of eq 4.18's normal matrix is below this:
  /// the rotation axes of the base spread by less than about asin(sqrt(ratio)).
  double planar_ratio = 0.05;
  /// Translation solvable when the second-smallest / largest eigenvalue of eq 4.18's normal matrix exceeds this.
  double translation_min_ratio = 1e-3;
  /// Ready only when eq 4.18's predicted standard deviation of t (residual
  /// variance times the largest eigenvalue of the inverse normal matrix, over
  /// the solved directions) is below this (m): a start from few pairs with
  /// small rotations was 1.5 m off (campus seed 7) where the calibration
  /// window's gates (1.0 / 0.3 m) cannot pull it in.
  double translation_max_std_m = 1e9;
  /// Fewer translation-valid pairs: the translation is not solved (one pair's
  /// rows have rank 2 and would read as planar motion about its own axis).
  std::size_t translation_min_pairs = 3;
  /// Planar motion of the rotations (sigma_min2 <= sigma_R < second-largest
  /// singular value: one common axis): rotation up to the rotation about the
  /// axis from eq 3.8-3.9, the rotation about it and x, y from the
  /// translations (eq 3.10-3.12), t along the axis 0 and flagged; off: stay collecting.
  bool planar_rotation = false;
  double planar_min_condition = 1e-3;  ///< eq 3.12 system's s_min / s_max below this: yaw or x, y unobservable
  /// Fewer stored pairs: no planar start (a few short handheld pairs also turn
  /// about one axis: 3 pairs after a shock read as planar and started 10 deg off).
  std::size_t planar_min_pairs = 3;
};

enum class OnlineHandEyeState { collecting, rotation_ready, ready };
std::string_view to_string(OnlineHandEyeState state);

/// What add() did with a pair.
enum class PairOutcome {
  stored,             ///< appended (store not full)
  replaced_smallest,  ///< store full: the stored pair with the smallest rotation was dropped for it
  dropped_small,      ///< store full and the new pair rotates least: the new pair was dropped
  rejected_invalid,   ///< a non-finite rotation or translation
};

struct OnlineHandEyeStatus {
  OnlineHandEyeState state = OnlineHandEyeState::collecting;
  std::array<double, 4> singular_values{};  ///< of the weighted Q_K (eq 4.16), descending; [2] is sigma_min2
  std::size_t pairs_stored = 0;
  std::size_t pairs_seen = 0;                       ///< every add() call, kept or not
  SE3 T_base_lidar;                                 ///< rotation valid from rotation_ready, translation when ready
  bool planar_motion = false;                       ///< translation along unobservable_axis_base fixed to 0
  Vec3 unobservable_axis_base = Vec3::Zero();       ///< unit, set when planar_motion
  std::array<double, 3> translation_eigenvalues{};  ///< of eq 4.18's normal matrix, ascending
  double rotation_rms_rad = 0.0;                    ///< rms residual angle (eq 4.17's phi) over the stored pairs
  std::size_t pairs_translation = 0;                ///< stored pairs whose translation is used (eq 4.18)
  double translation_std_m = -1.0;                  ///< eq 4.18's predicted standard deviation (-1: not solved)
  bool planar_rotation = false;                     ///< rotation about unobservable_axis_base from the translations (eq 3.10-3.12)
};

class OnlineHandEye {
 public:
  /// Throws std::invalid_argument for a config out of range.
  explicit OnlineHandEye(OnlineHandEyeConfig config = {});

  /// Adds one motion pair (eq 4.15 rows), re-weights the stored rows from the
  /// current estimate (eq 4.17) and re-solves. `translation_valid` false: the
  /// pair's rotations are used, its translations not (eq 4.18 skips it; e.g.
  /// its screw pitches disagree, eq 3.4, while its angles agree).
  PairOutcome add(const MotionPair& pair, bool translation_valid = true);
  const OnlineHandEyeStatus& status() const { return status_; }
  std::span<const MotionPair> pairs() const { return pairs_; }
  /// Forgets every pair (e.g. after an extrinsic shock).
  void reset();

 private:
  void solve();
  void solve_translation(std::span<const double> weights, const Quat& R_base_lidar);
  void solve_planar_rotation();

  OnlineHandEyeConfig config_;
  std::vector<MotionPair> pairs_;
  std::vector<double> rotation_angles_;  ///< min(angle(A), angle(B)) of each stored pair
  std::vector<bool> translation_valid_;  ///< per stored pair
  OnlineHandEyeStatus status_;
};

/// Eq 4.17: angle of the residual rotation X^-1 A^-1 X B (0 for an exact pair).
double hand_eye_residual_angle(const MotionPair& pair, const Quat& R_base_lidar);

}  // namespace mlidar::calib
