#pragma once
// One LiDAR's life in `mlidar slam` (thesis 4.5-4.6) as explicit states, each
// holding only what it needs and started fresh when entered:
//
//   Initializing --hand-eye ready (eq 4.15-4.18), or the rotation alone for
//                  StartParams::zero_translation_after_pairs pairs (t = 0)--> Calibrating
//   Initializing --StartParams::appearance_after_frames frames without that,
//                  then an ok appearance start (slam_appearance_start.hpp)--> Calibrating
//   Calibrating  --Algorithm 1 accepted L_calib windows (eq 4.21)---------> Trusted
//   Calibrating  --its windows' residual stays above the base's, none
//                  accepted (StartParams::reinitialize_*)-------------------> Initializing
//   Trusted      --an extrinsic shock (online only; the estimator decides)-> Initializing
//   Trusted      --a given extrinsic that disagrees with the map (fixed;
//                  the estimator decides, calib::ExtrinsicCheck)-----------> Calibrating
//
// Initializing runs the LiDAR's own odometry (its up direction T_g_lidar from
// the given extrinsic's rotation, or after a shock from its next scan's
// ground), pairs its motion with the trusted poses kPairStride frames apart,
// screens them with eq 3.4 and feeds calib::OnlineHandEye; under planar motion
// the start takes the height along the axis from the ground planes (eq
// 3.8-3.12, thesis 3.4.3.1) and names the unobservable directions.
// Calibrating deskews each scan once the next frame's pose is known, keeps the
// last N + 1 frames and solves the window for T_base_lidar against the trusted
// map (slam::solve_calibration_window); Algorithm 1 (calib::ConvergenceMonitor)
// accepts estimates and, at convergence, gives alpha Xi_calib.
// step() does one frame of the current state and returns the transition made.
// The report (SlamLidarReport) is derived from the track and the per-frame
// records; nothing is patched afterwards.
#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <variant>
#include <vector>

#include "mlidar/calib/convergence_monitor.hpp"
#include "mlidar/calib/online_hand_eye.hpp"
#include "mlidar/pipelines/slam_appearance_start.hpp"
#include "mlidar/pipelines/slam_config.hpp"
#include "mlidar/pipelines/slam_types.hpp"
#include "mlidar/slam/calibration_window.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {

/// Frames between the two ends of a motion pair (eq 4.13 pairs consecutive
/// frames). Measured on the simulated rhd handheld drive (80 frames, 10 Hz):
/// with consecutive frames sigma_min2 of Q_K reached only 0.13 < sigma_R =
/// 0.25 (rotations of 1-3 deg per frame); pairs 5 frames apart (overlapping,
/// one per frame) rotate 5x more.
constexpr std::size_t kPairStride = 5;
/// Frames of (base, LiDAR) scans kept while initializing for the ground heights (thesis 3.4.3.1) under planar motion.
constexpr std::size_t kGroundFrames = 5;

/// What a LiDAR's step sees of the frame.
struct TrackFrame {
  std::size_t index = 0;
  double stamp = 0.0;
  const Scan* base_scan = nullptr;              ///< the base LiDAR's scan at this frame, or null
  const slam::FrameResult* odometry = nullptr;  ///< the trusted odometry's result at this frame
  const slam::Odometry* trusted = nullptr;      ///< its maps, which calibration windows are matched against
  double base_residual_m = -1.0;                ///< the base's mean residual against the map (-1: none)
};

enum class TrackTransition { none, started_calibration, converged, reinitialized };

class LidarTrack {
 public:
  /// `setup.T_base_lidar`: the given extrinsic (identity when none). Online, only its rotation is used, as the
  /// up direction of the LiDAR's own odometry. `config` must outlive the track.
  LidarTrack(slam::LidarSetup setup, bool is_base, ExtrinsicSource source, const SlamConfig& config);

  LidarRole role() const;
  /// Name, model and the current extrinsic.
  const slam::LidarSetup& setup() const { return setup_; }

  /// One frame with this LiDAR's scan, or none (a gap: motion pairs and windows do not span it).
  TrackTransition step(const TrackFrame& frame, const std::optional<Scan>& scan, SlamLidarFrame& out);
  /// Initializing for StartParams::appearance_after_frames frames since it began, or since its last appearance start.
  bool appearance_due(std::size_t frame) const;
  /// Calibrates this LiDAR (`j` in `history`) by its appearance against the base's maps on the frames kept since it
  /// began initializing; an ok result starts the calibration window from it. Only when appearance_due(frame).
  TrackTransition start_by_appearance(const AppearanceHistory& history, const slam::LidarSetup& base, std::size_t j, std::size_t frame);
  /// Trusted -> Initializing after an extrinsic shock: hand-eye and Algorithm 1 start again; the own odometry
  /// restarts at the next scan with up from that scan's ground near the current extrinsic's.
  void restart_after_shock();
  /// Its extrinsic as given, not estimated here (the base's, fixed extrinsics'): what calib::ExtrinsicCheck judges.
  bool extrinsic_given() const;
  /// Records that its given extrinsic disagreed with the map; with `recalibrate`, Trusted -> Calibrating from that
  /// extrinsic (as `--calibrate refine` starts).
  void given_disagrees(ExtrinsicDisagreement disagreement, bool recalibrate);
  const std::optional<ExtrinsicDisagreement>& disagreement() const { return disagreement_; }

  /// The report after `frames` (this track's entries at `index` of each frame's lidars).
  SlamLidarReport report(std::span<const SlamFrame> frames, std::size_t index) const;

 private:
  struct PosePair {
    SE3 T_world_lidar;  ///< own odometry
    SE3 T_world_base;   ///< trusted odometry, same frame
  };
  struct Initializing {
    std::unique_ptr<slam::Odometry> own;  ///< null until the first scan after a shock
    calib::OnlineHandEye hand_eye;
    std::deque<PosePair> recent;               ///< the last kPairStride + 1 frames, without gaps
    std::deque<std::pair<Scan, Scan>> ground;  ///< the last kGroundFrames (base, LiDAR) scans
    std::size_t rotation_only_pairs = 0;       ///< pairs added in a row with the rotation ready, not the translation
    bool after_gap = false;                    ///< a frame without a scan since the own odometry's last one
    std::optional<std::size_t> first_frame;    ///< the frame it began at (its first step)
    std::size_t next_appearance = 0;           ///< the frame of its next appearance start
  };
  struct Pending {
    Scan scan;
    double stamp = 0.0;
    SE3 T_world_base;
  };
  struct Calibrating {
    std::vector<slam::CalibrationFrame> window;  ///< the last N + 1 frames
    std::optional<Pending> pending;              ///< the last scan, deskewed at the next frame
    std::size_t high_residual_windows = 0;       ///< windows not accepted with a high residual ratio since the last acceptance
    slam::FrontEndWorkspace workspace;
    slam::LidarFeatures features;
  };
  struct Trusted {
    std::optional<Mat6> covariance;  ///< alpha Xi_calib when it converged here; none when given (base, fixed)
    std::optional<calib::CalibrationCovariance> parts;
  };
  /// What the last hand-eye start gave, kept for the report.
  struct StartRecord {
    calib::OnlineHandEyeStatus status;  ///< the hand-eye's, as of its last pair
    TranslationStart translation_start = TranslationStart::none;
    std::vector<std::string> unobservable_from_motion;
    AxisTranslationSource axis_translation_source = AxisTranslationSource::none;
    std::vector<AppearanceAttempt> appearance;  ///< every appearance start, in order
  };

  std::variant<Initializing, Calibrating, Trusted> initial_state();
  Initializing start_initializing(bool own_odometry_now);
  std::unique_ptr<slam::Odometry> own_odometry() const;
  TrackTransition initialize(Initializing& state, const TrackFrame& frame, const Scan& scan);
  void add_motion_pair(Initializing& state, const PosePair& pose);
  void set_planar_height(const Initializing& state);
  TrackTransition calibrate(Calibrating& state, const TrackFrame& frame, const Scan& scan, SlamLidarFrame& out);
  /// The re-initialization test after a window that was not accepted (counts it in state).
  bool stays_far_from_the_map(Calibrating& state, const TrackFrame& frame, const SlamLidarFrame& out) const;

  const SlamConfig* config_;
  slam::LidarSetup setup_;  ///< T_base_lidar: the current extrinsic
  SE3 T_g_lidar_;           ///< the frame the own odometry runs in: the LiDAR's rotated so that z is up
  LidarRole initial_role_;
  SE3 given_T_base_lidar_;  ///< the extrinsic it started with
  std::optional<ExtrinsicDisagreement> disagreement_;
  calib::ConvergenceMonitor monitor_;  ///< Algorithm 1 for this LiDAR
  StartRecord start_;
  std::variant<Initializing, Calibrating, Trusted> state_;
};

}  // namespace mlidar::pipelines
