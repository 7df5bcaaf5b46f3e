#pragma once
// The records `mlidar slam`'s estimator produces: per frame (SlamFrame, one
// SlamLidarFrame per LiDAR) and per LiDAR at the end (SlamLidarReport), and the
// enums they use. Strings only at the JSON and terminal boundary (to_string).
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/calib/convergence_monitor.hpp"
#include "mlidar/calib/extrinsic_covariance.hpp"
#include "mlidar/calib/online_hand_eye.hpp"
#include "mlidar/core/se3.hpp"
#include "mlidar/pipelines/slam_appearance_start.hpp"
#include "mlidar/slam/odometry.hpp"
#include "mlidar/slam/odometry_window.hpp"

namespace mlidar::pipelines {

/// online: every auxiliary LiDAR is initialized (hand-eye) and calibrated;
/// refine: calibrated starting from the given extrinsics (no hand-eye: e.g.
/// planar motion, where the hand-eye cannot fix the rotation about the
/// common axis); fixed: the given extrinsics are used as they are.
enum class ExtrinsicSource { online, refine, fixed };
std::string_view to_string(ExtrinsicSource source);  ///< "online", "refine", "fixed" (metrics.json calibrate)

/// Where a LiDAR stands. The base is always trusted.
enum class LidarRole { initializing, calibrating, trusted };
std::string_view to_string(LidarRole role);

/// Seconds per frame of each back-end stage.
struct SlamStageSeconds {
  double odometry = 0.0;        ///< trusted odometry (front end, registration, map), restarts included
  double initialization = 0.0;  ///< untrusted LiDARs' own odometry and hand-eye
  double calibration = 0.0;     ///< calibrating LiDARs' front end, correspondences, window solve
  double shock = 0.0;           ///< per-LiDAR residuals and the trigger
  double window = 0.0;          ///< the sliding window over the trusted poses (window.refine_odometry)
};

/// One LiDAR at one frame.
struct SlamLidarFrame {
  LidarRole role = LidarRole::initializing;  ///< after this frame
  bool scan_missing = false;
  double lambda_min = -1.0;                   ///< smallest extrinsic-information eigenvalue of its window (-1: no window)
  bool accepted = false;                      ///< Algorithm 1 accepted this window's estimate
  std::optional<SE3> window_estimate;         ///< T_base_lidar of this frame's window (accepted or not)
  std::optional<Mat6> window_information;     ///< its extrinsic information ([t, r], left perturbation, 1/m^2)
  double window_residual_variance_m2 = -1.0;  ///< its residual variance per row (-1: no window)
  double window_step_m = -1.0;                ///< its estimate's change in the last re-matching pass, translation (-1: no window)
  double window_step_deg = -1.0;              ///< ... and rotation
  bool window_settled = false;                ///< that change was within the settle tolerances (else not accepted)
  double mean_residual_m = -1.0;              ///< against the map (-1: none)
  bool shock = false;                         ///< the re-calibration trigger fired
  bool reinitialized = false;                 ///< sent back to initialization (window residuals high, none accepted)
  /// Its given extrinsic judged against the map (calib::ExtrinsicCheck): the median ratio of its residual to the
  /// base's over the last frames (-1: not judged at this frame), and whether it crossed the limit here.
  double residual_ratio = -1.0;
  /// The map test at this frame (slam/map_consistency.hpp): its points' median distance to the other LiDARs' planes
  /// over that to its own (-1: not run at this frame).
  double map_ratio = -1.0;
  bool extrinsic_disagrees = false;
};

struct SlamFrame {
  double stamp = 0.0;
  SE3 T_world_base;                         ///< the trusted odometry's, or the window's latest estimate (window.refine_odometry)
  std::optional<slam::WindowPose> settled;  ///< window.refine_odometry: an earlier frame's final pose
  bool calibrating = false;                 ///< some LiDAR not trusted after this frame (online-calibration mode), else pure odometry
  bool lost = false;                        ///< the trusted odometry could not register this frame
  bool map_restarted = false;               ///< ... and started a new local map with it (slam::FrameResult::map_restarted)
  bool suspect = false;                     ///< its registration was doubtful (slam::FrameResult::suspect)
  /// The trusted odometry's pose covariance (slam/pose_covariance.hpp; left perturbation, world frame).
  Mat6 pose_covariance = Mat6::Zero();
  bool trusted_changed = false;  ///< the trusted set changes from the next frame on
  std::vector<SlamLidarFrame> lidars;
  SlamStageSeconds seconds;
  /// The trusted odometry's feature selection (none when off), for the LiDARs it registered (selection_lidars).
  std::optional<slam::SelectionSummary> selection;
  std::vector<std::string> selection_lidars;
  /// Uncertainty-aware mapping (empty / none when off): per LiDAR of the trusted odometry (`uncertainty_lidars`) the
  /// features too uncertain to register, and what entered the map.
  std::vector<std::size_t> uncertain_features;
  std::vector<std::string> uncertainty_lidars;
  std::optional<slam::MappingReport> mapping;
};

/// Where the calibration window's translation started at the last hand-eye start.
/// appearance: from the appearance against the base's map (slam_appearance_start.hpp).
enum class TranslationStart { none, hand_eye, zero, appearance };
std::string_view to_string(TranslationStart start);  ///< "hand_eye", "zero", "appearance"; "" for none
/// Planar motion: where the start's translation along the rotation axis came from.
enum class AxisTranslationSource { none, ground_planes, set_to_zero };
std::string_view to_string(AxisTranslationSource source);  ///< "ground planes", "set to 0"; "" for none

/// A given extrinsic that disagreed with the map: at which frame, by which median ratio of the LiDAR's residual to
/// the base's (calib::ExtrinsicCheck).
struct ExtrinsicDisagreement {
  std::size_t frame = 0;
  double residual_ratio = 0.0;  ///< -1 when judged by lost frames or by the map
  double map_ratio = -1.0;      ///< the map test's ratio when it judged (slam/map_consistency.hpp), else -1
  /// No frame after the first could be registered with it (SlamEstimator::kLostFromStartFrames lost in a row): with
  /// two or more LiDARs given, which one is wrong is not known, so each is judged so.
  bool frames_lost = false;
  bool recalibrated = false;     ///< calibrated online from the given extrinsic since (else used as given)
  bool from_first_frame = false;  ///< ... from the first frame on: found in an earlier run over the same frames
  bool after_shock = false;       ///< its extrinsic shock trigger had fired before: the mounting moved during the run
};

/// Per-LiDAR history for the report.
struct SlamLidarReport {
  std::string name;
  LidarRole role = LidarRole::initializing;
  SE3 T_base_lidar;                ///< current extrinsic
  std::optional<Mat6> covariance;  ///< alpha Xi_calib once converged ([t additive, r local], as extrinsics.yaml)
  std::optional<calib::CalibrationCovariance> covariance_parts;  ///< Xi_calib's terms (before alpha) once converged
  calib::OnlineHandEyeStatus initialization;
  std::optional<std::size_t> initialized_frame;      ///< last hand-eye completion
  std::optional<std::size_t> converged_frame;        ///< last convergence
  std::optional<std::size_t> first_converged_frame;  ///< first convergence (earlier than the last after a shock trigger)
  std::size_t accepted = 0;                          ///< accepted windows since the last (re)start
  std::size_t outliers = 0;                          ///< of those, left out of the mean at convergence (convergence.outlier_mads)
  std::size_t restarts = 0;                          ///< shock-triggered re-calibrations
  std::vector<std::size_t> shock_frames;
  std::size_t missing_frames = 0;
  std::vector<calib::WeakDirection> weak;            ///< directions of the last window below lambda_calib
  std::vector<std::size_t> reinitialization_frames;  ///< frames where a calibrating LiDAR went back to initialization
  /// Its given extrinsic found to disagree with the map (calib::ExtrinsicCheck), and that extrinsic (the current one
  /// differs once it was calibrated from there).
  std::optional<ExtrinsicDisagreement> disagreement;
  SE3 given_T_base_lidar;
  /// Extrinsic directions the motion left unobservable at the last hand-eye start (planar motion), in words.
  std::vector<std::string> unobservable_from_motion;
  AxisTranslationSource axis_translation_source = AxisTranslationSource::none;  ///< planar motion only
  TranslationStart translation_start = TranslationStart::none;  ///< zero: not solvable from motion; none before the first start
  std::vector<AppearanceAttempt> appearance_attempts;           ///< every appearance start, in order
};

}  // namespace mlidar::pipelines
