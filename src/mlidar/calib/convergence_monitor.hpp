#pragma once
// Monitoring calibration convergence, thesis Sec. 4.7.4, Algorithm 1. Per
// LiDAR, each sliding window gives the extrinsic estimate T_base_lidar and
// the 6x6 information matrix Lambda = J^T J of eq 4.21 w.r.t. that extrinsic:
//   lambda = smallest eigenvalue of Lambda (the degeneracy factor);
//   lambda > lambda_calib  -> the estimate is accepted (set as the system's extrinsic);
//   L_calib accepted       -> mean and covariance Xi_calib, calibration stops.
// Xi_calib is calib::calibration_covariance (extrinsic_covariance.hpp): the
// accepted estimates' scatter over their effective sample size (overlapping
// windows are autocorrelated) plus the windows' own mean covariance
// sigma^2 Lambda^-1 (when the caller gives the residual variance), in the
// tangent of extrinsics.yaml: [t additive, r local].
// (The thesis tests |L| > L_calib; here exactly L_calib accepted estimates
// converge, so `accepted_needed` is the sample size; with `outlier_mads` the
// mean and Xi_calib are of the estimates that agree with the median.) The eigenvectors of
// Lambda below lambda_calib are reported in words: the directions the motion
// and scene left unobservable (e.g. "translation z" under planar motion).
// Tangent order [t, r] as everywhere in mlidar; the names refer to the axes of
// the frame the caller's tangent lives in (for a left perturbation Exp(d) T
// of T_base_lidar: the base frame).
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/calib/extrinsic_covariance.hpp"
#include "mlidar/core/se3.hpp"

namespace mlidar::calib {

struct ConvergenceConfig {
  double lambda_calib = 70.0;        ///< accept a window's estimate when lambda_min exceeds it
  std::size_t accepted_needed = 25;  ///< L_calib: accepted estimates averaged at convergence
  /// Floor of the accepted estimates' autocorrelation time in Xi_calib: the
  /// frames a window spans (N + 1), as consecutive windows share N of them.
  double min_autocorrelation_time = 1.0;
  /// Per-axis 1-sigma of an error all windows of a run share (the map and
  /// poses they are matched against), added to Xi_calib: no statistic of the
  /// windows can see it. 0: none.
  double bias_translation_sd_m = 0.0;
  double bias_rotation_sd_deg = 0.0;
  /// At convergence, accepted estimates farther than this many robust sigmas
  /// (1.4826 MAD, floored at 2 mm / 0.02 deg) from the per-axis median are left
  /// out of the mean and Xi_calib (a region of weak, biased windows); 0: none.
  double outlier_mads = 0.0;
};

/// One eigen-direction of an information matrix.
struct WeakDirection {
  double eigenvalue = 0.0;
  Vec6 direction = Vec6::Zero();  ///< unit, [t, r], largest component positive
  std::string description;        ///< e.g. "translation z", "0.80 translation x + 0.60 rotation about z"
};

/// Eigenvectors of the symmetric `information` whose eigenvalue is below
/// `threshold`, weakest first.
std::vector<WeakDirection> weak_directions(const Mat6& information, double threshold);
/// Words for a [t, r] direction: the single axis name when one component
/// holds >= 90% of its squared norm, else the components holding >= 10%,
/// largest first, with their coefficients.
std::string describe_direction(const Vec6& direction);

/// Mean on SO(3) x R^3 (Karcher mean of the rotations, arithmetic mean of the
/// translations) and the sample covariance (divisor n - 1) of
/// [t_i - t_mean, Log(R_i R_mean^-1)] (rotation as a left perturbation).
struct ExtrinsicMean {
  SE3 mean;
  Mat6 covariance = Mat6::Zero();
  std::vector<Vec6> local_deviations;  ///< per sample [t_i - t_mean, Log(R_mean^-1 R_i)] (rotation local)
};
/// Throws std::invalid_argument for an empty set.
ExtrinsicMean extrinsic_mean(std::span<const SE3> samples);

/// Indices of the `deviations` ([t, r] tangent vectors) within `max_mads`
/// robust sigmas of the per-axis median on every axis; the robust sigma is
/// 1.4826 MAD, at least `sigma_floor` per axis. All of them when max_mads <= 0.
std::vector<std::size_t> robust_inliers(std::span<const Vec6> deviations, double max_mads, const Vec6& sigma_floor);

enum class CalibrationMode { calibrating, converged };
std::string_view to_string(CalibrationMode mode);

struct WindowVerdict {
  double lambda_min = 0.0;
  bool constrained = false;    ///< lambda_min > lambda_calib (line 5)
  bool accepted = false;       ///< constrained and settled: the estimate joins L (lines 6-7)
  bool converged_now = false;  ///< this window completed L_calib (lines 8-11)
};

/// Per-LiDAR state of Algorithm 1.
struct LidarCalibrationState {
  CalibrationMode mode = CalibrationMode::calibrating;
  std::vector<SE3> accepted;               ///< the set L (cleared at restart)
  std::vector<Mat6> accepted_covariances;  ///< their own covariances ([t, r local]) when given
  SE3 T_base_lidar;                        ///< last accepted estimate; the mean once converged
  Mat6 covariance = Mat6::Zero();          ///< Xi_calib once converged ([t additive, r local])
  CalibrationCovariance covariance_parts;  ///< its terms once converged
  double last_lambda_min = 0.0;
  std::size_t windows = 0;          ///< windows seen while calibrating
  std::size_t restarts = 0;         ///< restart() calls (re-calibrations)
  std::vector<WeakDirection> weak;  ///< of the last window's information below lambda_calib
  std::size_t outliers = 0;         ///< accepted estimates left out of the mean at convergence
};

class ConvergenceMonitor {
 public:
  /// `initial` holds each LiDAR's starting extrinsic (e.g. the online hand-eye's).
  /// Throws std::invalid_argument for an empty rig or accepted_needed < 2 or lambda_calib <= 0.
  ConvergenceMonitor(std::vector<SE3> initial, ConvergenceConfig config = {});

  /// Algorithm 1 for one window of LiDAR `lidar` (< size()). A converged
  /// LiDAR ignores windows (calibration stopped): the verdict says not accepted.
  /// A non-finite estimate or information is never accepted.
  /// `residual_variance` (> 0: the window's sigma^2 per residual row) makes the
  /// window's own covariance sigma^2 information^-1 part of Xi_calib; 0: unknown.
  /// `settled` false (the window's re-matching was still moving its estimate)
  /// keeps a constrained window out of L: a transient would bias the mean.
  WindowVerdict add_window(std::size_t lidar, const SE3& T_base_lidar, const Mat6& information, double residual_variance = 0.0,
                           bool settled = true);

  /// Back to calibrating from the current extrinsic, L emptied (the re-calibration trigger).
  void restart(std::size_t lidar);

  const LidarCalibrationState& lidar(std::size_t index) const { return lidars_.at(index); }
  std::size_t size() const { return lidars_.size(); }
  bool all_converged() const;

 private:
  ConvergenceConfig config_;
  std::vector<LidarCalibrationState> lidars_;
};

}  // namespace mlidar::calib
