#pragma once
// The M-LOAM estimator of `mlidar slam` (thesis Ch. 4, Sec. 4.5-4.7), one
// frame at a time, over LiDARs given base first. It keeps:
//   - the trusted odometry: the trusted LiDARs feed one slam::Odometry
//     (scan-to-map, their features together: the pure-odometry mode, eq 4.22),
//     which gives T_world_base and the map. Start: {base} (online, refine) or
//     every LiDAR (fixed);
//   - one LidarTrack per LiDAR (slam_lidar_track.hpp): initializing (online
//     hand-eye), calibrating (the calibration window and Algorithm 1) or
//     trusted; a converged LiDAR joins the trusted odometry;
//   - the shock detector: each trusted LiDAR's mean residual against the map
//     per frame feeds calib::ShockDetector; a trigger sends that LiDAR back to
//     initializing (online only; the base's trigger is reported, it defines
//     the base frame);
//   - optionally the sliding window over the trusted poses (window.refine_odometry);
//   - while some LiDAR initializes, the last frames for its appearance start
//     (slam_appearance_start.hpp): the base's scans and trusted poses, the
//     initializing LiDARs' scans at the refinement's candidate frames.
// A change of the trusted set takes effect at the next frame
// (Odometry::set_lidars): the world, the pose history and the local map are
// kept (an earlier version restarted the odometry and its map there; the
// fresh map cost 0.3 deg of rotation drift on rhd handheld). A LiDAR without a scan at a frame (nullopt) is
// skipped there: a trusted one contributes nothing, an untrusted one's
// motion pairs and windows do not span the gap.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "mlidar/calib/extrinsic_check.hpp"
#include "mlidar/calib/shock_detector.hpp"
#include "mlidar/pipelines/slam_config.hpp"
#include "mlidar/pipelines/slam_lidar_track.hpp"
#include "mlidar/pipelines/slam_pose_window.hpp"
#include "mlidar/pipelines/slam_types.hpp"
#include "mlidar/slam/odometry.hpp"
#include "mlidar/slam/pose_covariance.hpp"

namespace mlidar::pipelines {

class SlamEstimator {
 public:
  /// Frames lost in a row from the second on after which every given auxiliary extrinsic is judged to disagree
  /// with the map (calib::ExtrinsicCheck sees no residuals then): Table 4.6's shock on `rv` loses every frame.
  static constexpr std::size_t kLostFromStartFrames = 5;
  /// Planar neighbourhoods the map test needs of a LiDAR, of its own and of the others', to judge it.
  static constexpr std::size_t kMapTestPlanes = 100;

  /// `lidars`: base first. Online, their extrinsics serve only as the up
  /// direction of each LiDAR's own odometry (their rotation; give identity
  /// when unknown); the estimate never starts from them. `disagreed[j]` (empty: none): LiDAR j's given extrinsic
  /// is known to disagree with the map (from an earlier run over the same frames): it is calibrated from it from
  /// the first frame on. Throws std::invalid_argument for no LiDARs.
  SlamEstimator(SlamConfig config, std::vector<slam::LidarSetup> lidars, ExtrinsicSource source,
                const std::vector<std::optional<ExtrinsicDisagreement>>& disagreed = {});
  SlamEstimator(const SlamEstimator&) = delete;
  SlamEstimator& operator=(const SlamEstimator&) = delete;

  /// scans[j]: LiDAR j's scan at `stamp` or nullopt (missing). Stamps increasing.
  SlamFrame process(double stamp, const std::vector<std::optional<Scan>>& scans);

  /// Each LiDAR's report after `frames`, the records process() returned (all of them, in order).
  std::vector<SlamLidarReport> lidar_reports(std::span<const SlamFrame> frames) const;
  /// window.refine_odometry: the frames whose pose has not settled yet, at their latest estimates.
  std::vector<slam::WindowPose> unsettled_poses() const;
  /// The current local maps (planes then edges) in the world frame.
  const slam::Odometry& trusted_odometry() const { return *odometry_; }
  /// LiDAR j's state (for tests and reports).
  const LidarTrack& track(std::size_t j) const { return tracks_.at(j); }

 private:
  /// The trusted LiDARs' setups; sets trusted_ to their indices.
  std::vector<slam::LidarSetup> trusted_setups();
  /// The base's mean residual against the map at this frame (-1: none).
  double base_residual(const std::vector<std::optional<Scan>>& scans) const;
  void keep_for_appearance(std::size_t k, double stamp, const std::vector<std::optional<Scan>>& scans);
  void step_tracks(const TrackFrame& frame, const std::vector<std::optional<Scan>>& scans, SlamFrame& out);
  void detect_shocks(SlamFrame& out);
  void check_given_extrinsics(SlamFrame& out);
  /// The map test (slam/map_consistency.hpp) of the given auxiliary extrinsics: the LiDARs that disagree.
  std::vector<std::size_t> map_disagreements(const std::vector<bool>& given, SlamFrame& out) const;

  SlamConfig config_;  ///< the tracks refer to it
  ExtrinsicSource source_;
  std::vector<LidarTrack> tracks_;
  calib::ShockDetector shock_;
  calib::ExtrinsicCheck extrinsic_check_;
  std::unique_ptr<slam::Odometry> odometry_;  ///< over the trusted LiDARs
  std::vector<std::size_t> trusted_;          ///< indices in odometry_'s LiDAR order
  slam::FrameResult last_odometry_;
  slam::PoseCovarianceChain pose_covariance_;
  std::optional<SlamPoseWindow> pose_window_;  ///< window.refine_odometry
  AppearanceHistory history_;                  ///< the last appearance_after_frames + 1 frames while some LiDAR initializes
  bool trusted_changed_ = false;
  std::size_t frames_ = 0;
  std::size_t lost_from_start_ = 0;  ///< frames lost in a row from the second on (0 once one was registered)
  bool registered_once_ = false;
  bool trusted_set_changed_ = false;  ///< ever: the map's sources then no longer follow one LiDAR order
};

}  // namespace mlidar::pipelines
