#pragma once
// The M-LOAM estimator of `mlidar slam` (thesis Ch. 4, Sec. 4.5-4.7), one
// frame at a time, over LiDARs given base first:
//   - a trusted set of LiDARs feeds a slam::Odometry (scan-to-map, their
//     features together: the pure-odometry mode, eq 4.22); it gives
//     T_world_base. Start: {base} (online) or every LiDAR (fixed).
//   - initialization of each untrusted LiDAR j (eq 4.15-4.18): its own
//     odometry gives B_k, the trusted poses give A_k, for
//     frames 5 apart (one overlapping pair per frame), into
//     calib::OnlineHandEye until it is ready (a pair failing eq 3.4's pitch
//     test gives its rotation only; with the rotation but no translation for
//     StartParams::zero_translation_after_pairs pairs, the window starts
//     from t = 0; under planar motion eq 3.8-3.12 and the ground planes give
//     the start and the unobservable directions are reported)
//     (slam_start.cpp);
//   - online calibration of j (eq 4.21): j's features (deskewed, in its own
//     frame) on the last N + 1 frames, whose poses the trusted map fixes, are
//     matched against that map and the window is solved for T_base_lidar_j;
//     (estimate, information) go to Algorithm 1 (calib::ConvergenceMonitor):
//     accepted estimates become j's extrinsic; on convergence j joins the
//     trusted set with covariance alpha Xi_calib (calib::calibration_covariance:
//     the accepted estimates' scatter over their effective sample size, tau
//     at least N + 1, plus the windows' own sigma^2 Lambda^-1);
//   - re-initialization: a calibrating LiDAR whose windows, none accepted,
//     keep a map residual above StartParams's ratio times the base's goes
//     back to initialization (its hand-eye start was wrong);
//   - extrinsic shock: each trusted LiDAR's mean residual against the map per
//     frame feeds calib::ShockDetector; a trigger sends that LiDAR back to
//     initialization (hand-eye and Algorithm 1 restarted; its own odometry
//     restarted at its next scan with up from that scan's ground, as the
//     shock tilted the old extrinsic's up).
// A change of the trusted set takes effect at the next frame
// (Odometry::set_lidars): the world, the pose history and the local map are
// kept (an earlier version restarted the odometry and its map there; the
// fresh map cost 0.3 deg of rotation drift on rhd handheld). A LiDAR without a scan at a frame (nullopt) is
// skipped there: a trusted one contributes nothing, an untrusted one's
// motion pairs and windows do not span the gap.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/calib/convergence_monitor.hpp"
#include "mlidar/calib/online_hand_eye.hpp"
#include "mlidar/calib/shock_detector.hpp"
#include "mlidar/pipelines/slam_config.hpp"
#include "mlidar/pipelines/slam_pose_window.hpp"
#include "mlidar/slam/map_correspondences.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {

/// online: every auxiliary LiDAR is initialized (hand-eye) and calibrated;
/// refine: calibrated starting from the given extrinsics (no hand-eye: e.g.
/// planar motion, where the hand-eye cannot fix the rotation about the
/// common axis); fixed: the given extrinsics are used as they are.
enum class ExtrinsicSource { online, refine, fixed };

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
  double lambda_min = -1.0;        ///< smallest extrinsic-information eigenvalue of its window (-1: no window)
  bool accepted = false;           ///< Algorithm 1 accepted this window's estimate
  std::optional<SE3> window_estimate;  ///< T_base_lidar of this frame's window (accepted or not)
  std::optional<Mat6> window_information;  ///< its extrinsic information ([t, r], left perturbation, 1/m^2)
  double window_residual_variance_m2 = -1.0;  ///< its residual variance per row (-1: no window)
  double window_step_m = -1.0;     ///< its estimate's change in the last re-matching pass, translation (-1: no window)
  double window_step_deg = -1.0;   ///< ... and rotation
  bool window_settled = false;     ///< that change was within the settle tolerances (else not accepted)
  double mean_residual_m = -1.0;   ///< against the map (-1: none)
  bool shock = false;              ///< the re-calibration trigger fired
  bool reinitialized = false;      ///< sent back to initialization (window residuals high, none accepted)
};

struct SlamFrame {
  double stamp = 0.0;
  SE3 T_world_base;  ///< the trusted odometry's, or the window's latest estimate (window.refine_odometry)
  std::optional<slam::WindowPose> settled;  ///< window.refine_odometry: an earlier frame's final pose
  bool calibrating = false;  ///< some LiDAR not trusted after this frame (online-calibration mode), else pure odometry
  bool lost = false;         ///< the trusted odometry could not register this frame
  bool trusted_changed = false;  ///< the trusted set changes from the next frame on
  std::vector<SlamLidarFrame> lidars;
  SlamStageSeconds seconds;
};

/// Per-LiDAR history for the report.
struct SlamLidarReport {
  std::string name;
  LidarRole role = LidarRole::initializing;
  SE3 T_base_lidar;                    ///< current extrinsic
  std::optional<Mat6> covariance;      ///< alpha Xi_calib once converged ([t additive, r local], as extrinsics.yaml)
  std::optional<calib::CalibrationCovariance> covariance_parts;  ///< Xi_calib's terms (before alpha) once converged
  calib::OnlineHandEyeStatus initialization;
  std::optional<std::size_t> initialized_frame;  ///< last hand-eye completion
  std::optional<std::size_t> converged_frame;    ///< last convergence
  std::optional<std::size_t> first_converged_frame;  ///< first convergence (earlier than the last after a shock trigger)
  std::size_t accepted = 0;            ///< accepted windows since the last (re)start
  std::size_t outliers = 0;            ///< of those, left out of the mean at convergence (convergence.outlier_mads)
  std::size_t restarts = 0;            ///< shock-triggered re-calibrations
  std::vector<std::size_t> shock_frames;
  std::size_t missing_frames = 0;
  std::vector<calib::WeakDirection> weak;  ///< directions of the last window below lambda_calib
  std::vector<std::size_t> reinitialization_frames;  ///< frames where a calibrating LiDAR went back to initialization
  /// Extrinsic directions the motion left unobservable at the last hand-eye start (planar motion), in words.
  std::vector<std::string> unobservable_from_motion;
  std::string axis_translation_source;  ///< planar: "ground planes" or "set to 0"; else empty
  std::string translation_start;  ///< "hand_eye" or "zero" (not solvable from motion) at the last start; empty before
};

class SlamEstimator {
 public:
  /// `lidars`: base first. Online, their extrinsics serve only as the up
  /// direction of each LiDAR's own odometry (their rotation; give identity
  /// when unknown); the estimate never starts from them. Throws std::invalid_argument for no LiDARs.
  SlamEstimator(SlamConfig config, std::vector<slam::LidarSetup> lidars, ExtrinsicSource source);
  ~SlamEstimator();
  SlamEstimator(const SlamEstimator&) = delete;
  SlamEstimator& operator=(const SlamEstimator&) = delete;

  /// scans[j]: LiDAR j's scan at `stamp` or nullopt (missing). Stamps increasing.
  SlamFrame process(double stamp, const std::vector<std::optional<Scan>>& scans);

  std::vector<SlamLidarReport> lidar_reports() const;
  /// window.refine_odometry: the frames whose pose has not settled yet, at their latest estimates.
  std::vector<slam::WindowPose> unsettled_poses() const;
  /// The current local maps (planes then edges) in the world frame.
  std::vector<Eigen::Vector3f> map_points() const;

 private:
  struct Track;
  void run_trusted_odometry(double stamp, const std::vector<std::optional<Scan>>& scans, SlamFrame& out);
  /// The trusted LiDARs' setups; sets trusted_ to their indices.
  std::vector<slam::LidarSetup> trusted_setups();
  void initialize(std::size_t j, double stamp, const Scan& scan, const Scan* base_scan, std::size_t frame_index, SlamLidarFrame& out);
  void set_planar_height(Track& track);
  void check_reinitialization(std::size_t frame_index, SlamFrame& out);
  void calibrate(std::size_t j, double stamp, const Scan& scan, std::size_t frame_index, SlamLidarFrame& out);
  void detect_shocks(std::size_t frame_index, SlamFrame& out);
  /// Back to initialization: hand-eye, pair history and Algorithm 1 restarted (shock and re-initialization share it).
  void restart_initialization(std::size_t j);
  void make_untrusted(std::size_t j);
  /// A new own odometry for initializing LiDAR j, its up from `scan`'s ground near the old one.
  void restart_own_odometry(std::size_t j, const Scan& scan);

  SlamConfig config_;
  ExtrinsicSource source_;
  std::vector<std::unique_ptr<Track>> tracks_;
  calib::ConvergenceMonitor monitor_;
  calib::ShockDetector shock_;
  std::unique_ptr<slam::Odometry> odometry_;  ///< over the trusted LiDARs
  std::vector<std::size_t> trusted_;          ///< indices in odometry_'s LiDAR order
  slam::FrameResult last_odometry_;
  std::optional<SlamPoseWindow> pose_window_;  ///< window.refine_odometry
  bool trusted_changed_ = false;
  std::size_t frames_ = 0;
};

}  // namespace mlidar::pipelines
