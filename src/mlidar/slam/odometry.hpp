#pragma once
// Multi-LiDAR scan-to-map odometry with known extrinsics (the thesis's pure
// odometry mode, eq 4.22, as a frame-to-local-map registration):
//   1. predict the pose by constant velocity;
//   2. per LiDAR, in parallel: front end, deskewed with the predicted velocity
//      to the frame's time centroid t_c (mean capture time of its points);
//   3. register all LiDARs' features at once against the local maps;
//      when the match ratio is poor, retry from several yaw offsets
//      (large unmodelled turns) and from the previous pose, and keep the
//      tightest; flag the frame lost if none matches well, suspect if the
//      tightest still fits worse than the recent frames or another
//      alignment fits as well (registration_trust.hpp);
//   4. add the features of a trusted frame to the voxel-hashed local maps
//      (never a suspect or lost one's), drop far voxels;
//   5. adapt the correspondence threshold from the prediction error
//      (KISS-ICP's adaptive threshold, Vizzo et al. 2023, eq 6-7);
//   6. report T_world_base at the frame stamp: the registered pose at t_c
//      moved back by t_c under the velocity between the last two t_c poses.
// Why the time centroid: a velocity error dv shifts a cloud deskewed to a
// time t_ref rigidly by about (t_c - t_ref) dv. Registered at the stamp
// (t_ref = 0, t_c = 0.05 s for a 10 Hz sweep from the stamp, more for LiDARs
// with sweep offsets), each pose error feeds the next velocity:
// e_k = -(t_c / dt) (e_{k-1} - e_{k-2}), undamped at t_c = dt / 2 (a
// growing period-2 oscillation beyond). At t_ref = t_c the shift vanishes
// to first order, and so does the
// bias of the first frames, mapped before any velocity is known; these are
// deskewed again (and the map rebuilt) once frame 2 gives the first velocity.
// The world frame is the base at the first stamp: at that point the poses and
// map are also moved from the first time centroid to the first stamp.
// Works with one LiDAR too (T_base_lidar = identity): each LiDAR's own motion.
#include <limits>
#include <optional>
#include <vector>

#include "mlidar/slam/frontend.hpp"
#include "mlidar/slam/point_uncertainty.hpp"
#include "mlidar/slam/registration_trust.hpp"
#include "mlidar/slam/scan_to_map.hpp"
#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {

struct OdometryConfig {
  FrontEndConfig front_end;
  RegistrationConfig registration;
  double plane_voxel_m = 1.0;
  double edge_voxel_m = 1.0;
  int plane_points_per_voxel = 20;
  int edge_points_per_voxel = 10;
  /// RegistrationConfig::plane_neighbors_max for a frame whose features are mostly voxel samples (clouds with no
  /// model and no scan rows: ring-less keyframes, solid-state scanners), whose map is evenly dense; range-image
  /// (LOAM) features keep registration.plane_neighbors_max. Measured 2026-12-07 (docs/benchmarks.md "More
  /// neighbours for the plane fit"): 8 on real Ouster keyframes, 5 on the simulated 16-beam rigs.
  int voxel_plane_neighbors_max = 8;
  /// RegistrationConfig::plane_min_extent_m in units of the range 1-sigma of the noisiest LiDAR (its model's, else
  /// uncertainty.range_sigma_m); the odometry sets it from its LiDARs (construction, set_lidars). Measured
  /// 2026-12-07 (docs/benchmarks.md "Plane patches narrower than the range noise"): 0.5 takes issue 9's handheld
  /// protocol (5 cm noise) from ATE 8.1 to 7.1 mm and its online calibration from 0.105 to 0.069 deg; a whole
  /// sigma leaves too few planes in a room.
  double plane_min_extent_sigmas = 0.5;
  double local_map_radius_m = 100.0;
  double initial_threshold_m = 2.0;  ///< correspondence distance before any motion is seen
  double min_threshold_m = 0.3;
  double min_motion_m = 0.1;        ///< predictions moving less are not used to adapt
  double reference_range_m = 30.0;  ///< converts rotation error into metres
  /// When a registration is believed (registration_trust.hpp): its absolute
  /// bounds (mean |r| at most 0.2 m: the adaptive threshold grows after hard
  /// turns and then lets a wrong alignment match well, real BALM keyframes
  /// 45->46, a 21 deg turn) and its bound relative to the recent frames.
  /// Untrusted, the retries run; the best of all is kept and judged.
  TrustConfig trust;
  std::vector<double> retry_yaw_deg = {15, -15, 30, -30, 45, -45, 60, -60};
  /// The retries also start from the previous pose (no motion), turned by the
  /// same yaws: after a second of handheld motion the constant-velocity
  /// prediction can be metres off.
  bool retry_from_previous_pose = true;
  /// The retries' coarse pass (from each start, at the wide threshold) uses
  /// every n-th feature and stops at a looser convergence (it only seeds the
  /// fine pass); the fine pass on every feature then runs from each distinct
  /// coarse end pose (closer than a quarter of trust.distinct_* in both
  /// translation and rotation counts as the same: 0.05 m and 0.5 deg), except
  /// those that converged to a fit no registration may have (mean |r| above
  /// trust.max_mean_residual_m; the tightest one always runs). Real BALM
  /// keyframes, 10 retried frames: 34 full registrations each before, 23.8 s
  /// of registration in a 26.7 s run; after, 1-2 fine passes per frame, the
  /// same pair errors (docs/benchmarks.md "Cheaper retries"). 1: every feature.
  std::size_t retry_coarse_stride = 8;
  int retry_coarse_iterations = 100;
  double retry_coarse_convergence_m = 0.01;
  double retry_coarse_convergence_rad = 1e-3;
  /// A frame whose features are mostly voxel samples (ring-less keyframes, solid-state scanners) first registers
  /// every n-th feature from the prediction with the retries' coarse settings, then every feature from where that
  /// ended; 1: every feature from the prediction. Such frames come from keyframes up to a second apart whose
  /// prediction may be decimetres and degrees off: from there the full registration took 13 iterations on average
  /// (every one searching the map for every feature again), and 6 of 100 keyframes were retried. Real BALM
  /// keyframes 0.5 s apart, 2026-12-07 (docs/benchmarks.md "A coarse pass before the full registration"): 4.7 full
  /// iterations, 1 retried frame instead of 6, whole run 7.3 -> 3.3 s, the same pair errors. Range-image frames
  /// (10 Hz rigs, the prediction a few cm off) keep the prediction: there it neither saved time nor changed the
  /// accuracy beyond noise.
  int voxel_coarse_stride = 8;
  /// Frames this long after the last registered one (seconds; lost frames between count as the gap: empty scans and
  /// absent frames alike) always run the retries and are judged with their rivals, trusted first registration or not.
  double always_retry_after_s = 1.5;
  /// After this many frames in a row whose registration failed (lost with features; frames without any, a gap in
  /// the input, are not counted), the next frame with points starts a new local map at its predicted pose (0: never):
  /// registered against a map it has left or from a prediction that went wrong (a velocity never known, a gap while
  /// turning), every later frame would be lost too. The restart frame is itself lost (its pose is the prediction,
  /// FrameResult::map_restarted); the frames after it are registered against the new map, so their relative motion
  /// is measured again while the offset to the trajectory before is the prediction's. Frames of voxel samples
  /// (clouds without scan rows: ring-less keyframes, solid-state scanners) never restart: on simulated solid-state
  /// keyframes 0.1-7 s apart, maps started again from one sparse keyframe let 1 wrong pair of 290 pass as trusted
  /// (docs/benchmarks.md "Failed registrations in a row start a new local map").
  std::size_t restart_after_lost = 5;
  /// After this many frames in a row with points that were not trusted (suspect or lost), the next frame with points
  /// starts a new local map as after restart_after_lost (0: never). Only trusted frames enter the map, so a map the
  /// drive has left behind stays behind: after 2 s without scans (rv seed 3, scans 30-49 blanked) the right LiDAR
  /// alone registered every later frame degenerate or ambiguous against it, 50 frames suspect and 49 pairs off, to the
  /// end of the drive. Frames of voxel samples never restart (as restart_after_lost).
  std::size_t restart_after_suspect = 10;
  /// After a trusted registration, deskew the frame's features again with the
  /// velocity it measured (the prediction's is a frame late) and register once
  /// more from there, before they enter the map. Off: it costs a second
  /// registration (+40-55 % CPU per frame; ATE -10 to -50 % on handheld rhd,
  /// docs/benchmarks.md "Deskew of the base").
  bool refine_deskew = false;
  /// Deskew the features again between registration iterations with the
  /// velocity the current estimate implies (MotionDeskew in scan_to_map.hpp),
  /// and map them with the last one: the prediction's velocity is a frame late
  /// (ATE -20 to -45 % on the handheld protocol for +5 % CPU: docs/benchmarks.md).
  bool deskew_in_registration = true;
  /// Uncertainty-aware mapping (thesis sec 4.8, point_uncertainty.hpp): registration rows weighted by each
  /// feature's covariance, map points with theirs, uncertain ones left out. Off by default.
  UncertaintyConfig uncertainty;
};

/// What a mapped frame added to the map under uncertainty-aware mapping (FrameResult::mapping).
struct MappingReport {
  std::size_t features = 0;           ///< features offered to the map
  std::size_t dropped_uncertain = 0;  ///< of those, with tr(Sigma) > w
  std::size_t points_added = 0;       ///< after eq 4.30's filter (== features - dropped without it)
  double median_trace_m2 = 0.0;       ///< of the offered features' tr(Sigma)
};

/// A frame's feature selection as the metrics report it (FrameResult::selection_summary).
struct SelectionSummary {
  SelectionReport report;                   ///< without its `chosen` positions
  std::vector<std::size_t> lidar_features;  ///< per LiDAR (construction order)
  std::vector<std::size_t> lidar_selected;  ///< of those, the chosen
  std::optional<Degeneracy> full_set_degeneracy;
  bool degenerate_scene = false;
  /// The above with the registration's report; none when it selected no features.
  std::optional<SelectionSummary> selection_summary() const;
};

struct FrameResult {
  double stamp = 0.0;
  SE3 T_world_base;                 ///< at `stamp`
  double centroid_time = 0.0;       ///< mean point time, seconds after `stamp`
  RegistrationResult registration;  ///< its T_world_base: the pose at stamp + centroid_time
  StageSeconds seconds{};
  std::size_t points_in = 0;
  std::size_t edge_features = 0;
  std::size_t plane_features = 0;
  double threshold_m = 0.0;
  bool retried = false;
  Trust trust = Trust::kTrusted;
  double recent_residual_m = 0.0;  ///< the recent frames' median mean |r| it was judged against (NaN: none)
  /// No acceptable registration: the pose is the prediction, not mapped (except by a map_restarted frame).
  bool lost() const { return trust == Trust::kLost; }
  /// This frame started a new local map at its predicted pose after OdometryConfig::restart_after_lost frames lost
  /// or restart_after_suspect not trusted in a row (it is lost: the trajectory after it joins the one before through
  /// the prediction alone).
  bool map_restarted = false;
  /// Acceptable but not trusted (`trust` says why): the pose is kept, not mapped.
  bool suspect() const { return trust == Trust::kResidual || trust == Trust::kAmbiguous || trust == Trust::kDegenerate; }
  /// Lost or suspect: its pose must not feed a calibration, a window or a map.
  bool flagged() const { return lost() || suspect(); }
  /// Per LiDAR (construction order): mean |r| of its matched features at the
  /// registration's last linearisation; NaN when it matched none (and on the first frame).
  std::vector<double> lidar_mean_residual_m;
  /// Per LiDAR (construction order): its features, and with feature selection
  /// (RegistrationResult::selection) how many of them the registration chose.
  std::vector<std::size_t> lidar_features;
  std::vector<std::size_t> lidar_selected;
  /// With uncertainty-aware mapping, per LiDAR: features left out (before lidar_features) for tr(Sigma) > w in the base frame.
  std::vector<std::size_t> lidar_uncertain;
  /// Per LiDAR (construction order): its range image's rows (0: voxel fallback) and where they came from.
  std::vector<int> lidar_rows;
  std::vector<RowSource> lidar_row_source;
  /// With adaptive feature selection: the full set's degeneracy factors where
  /// this frame evaluated them, and whether the scene counts as degenerate (sec 5.4.4).
  std::optional<Degeneracy> full_set_degeneracy;
  bool degenerate_scene = false;
  /// The above with the registration's report; none when it selected no features.
  std::optional<SelectionSummary> selection_summary() const;
  /// With uncertainty-aware mapping, for a frame whose features entered the map.
  std::optional<MappingReport> mapping;
};

class Odometry {
 public:
  /// Throws std::invalid_argument for no LiDARs.
  Odometry(OdometryConfig config, std::vector<LidarSetup> lidars);

  /// frame.scans in the order of the LiDARs given at construction (or to set_lidars); stamps increasing.
  FrameResult process(const Frame& frame);

  /// From the next frame on, registers and maps these LiDARs (e.g. one more,
  /// or new extrinsics); the world, the pose history and the local maps are
  /// kept. Throws std::invalid_argument for no LiDARs.
  void set_lidars(std::vector<LidarSetup> lidars);

  /// From the next frame on, registers on every feature (paused) or with the configured selection.
  void set_selection_paused(bool paused) { selection_paused_ = paused; }

  const VoxelMap& plane_map() const { return plane_map_; }
  const VoxelMap& edge_map() const { return edge_map_; }
  const std::vector<LidarSetup>& lidars() const { return lidars_; }
  const OdometryConfig& config() const { return config_; }
  /// The last frame's features per LiDAR (construction order), in the base
  /// frame at that frame's time centroid, i.e. at FrameResult::registration.T_world_base.
  const std::vector<LidarFeatures>& lidar_features() const { return features_; }

 private:
  /// The constant velocity of the prediction: between the last registered centroid pose and the one before it
  /// that was registered (zero before two). Lost frames' poses are predictions with this velocity.
  BodyVelocity latest_velocity() const { return velocity_; }
  /// Where a velocity measured at this frame starts: the last registered centroid pose. After lost frames the last
  /// pose is a prediction, and a velocity from it would put the whole gap's prediction error into one frame's time.
  const StampedPose& velocity_anchor() const { return last_registered_; }
  RegistrationResult register_robustly(const SE3& prediction, double centroid_stamp, const MotionDeskew* motion, FrameResult& frame);
  /// judge_degenerate_correction, and a degenerate registration after a frame not trusted is suspect (kDegenerate).
  Trust judge_degenerate(Trust trust, const RegistrationResult& r, const SE3& prediction) const;
  /// After a registration with MotionDeskew: the frame's features deskewed with the velocity it ended with.
  void apply_registered_deskew(const BodyVelocity& used, const BodyVelocity& registered);
  /// 1 + (TrustConfig::voxel_residual_ratio - 1) x the share of voxel samples among this frame's features.
  double residual_scale() const;
  /// The current frame's share of voxel samples among its features, in [0, 1].
  double voxel_sample_share() const;
  /// Most of the frame's features are voxel samples (clouds without a model or scan rows): they get their own
  /// plane fit (voxel_plane_neighbors_max) and a coarse pass first (voxel_coarse_stride).
  bool mostly_voxel_samples() const { return voxel_sample_share() > 0.5; }
  TrustRule trust_rule() const;
  /// The registration settings of this frame: the plane fit by its kind of features (voxel_plane_neighbors_max when
  /// mostly voxel samples); with adaptive feature selection,
  /// lambda is evaluated again every degeneracy_interval_s and sets M (sec 5.4.4).
  RegistrationConfig frame_registration(const SE3& prediction, double threshold, double centroid_stamp, FrameResult& frame);
  /// Registrations from the retry starts (prediction and previous pose, turned).
  void add_retries(const SE3& prediction, double threshold, const MotionDeskew* motion, std::vector<RegistrationResult>& out) const;
  void refine_deskew(const BodyVelocity& used, double centroid_stamp, FrameResult& result);
  void adapt_threshold(const SE3& prediction, const SE3& estimate);
  /// Features of several LiDARs concatenated (edges, then planes, LiDAR after LiDAR): how many of each.
  struct FeatureBlock {
    std::size_t edges = 0, planes = 0;
    UncertainPose T_base_lidar;  ///< the extrinsic and alpha Xi it was seen through
    double range_sigma_m = 0.0;
  };
  /// The current frame's features per LiDAR and, with uncertainty-aware mapping, their base-frame covariances.
  void collect_features(FrameResult& result);
  /// The registrations' QueryCovariances (nullptr without uncertainty-aware mapping).
  const QueryCovariances* query_covariances() const { return query_covariances_ ? &*query_covariances_ : nullptr; }
  /// `Xi_reg`: the registration's covariance (left, world) that uncertainty-aware mapping propagates.
  std::optional<MappingReport> update_map(const SE3& T_world_centroid, const LidarFeatures& features,
                                          const std::vector<FeatureBlock>& blocks, const Mat6& Xi_reg);
  /// The retries' coarse pass settings (every feature of the strided set, the loose convergence).
  RegistrationConfig coarse_registration() const;
  /// Where the frame's full registration starts: the prediction, or for a frame of voxel samples the end of a
  /// coarse pass from it (voxel_coarse_stride) when that converged.
  SE3 registration_start(const SE3& prediction, double threshold) const;
  /// At the second frame, once a velocity is known: moves the world from the
  /// first frame's centroid pose to its stamp pose and rebuilds the map from
  /// the first two frames' features deskewed with that velocity.
  void restart_with_first_velocity(double first_centroid_time, bool second_unmapped);
  /// A new local map from the next frame on, as at the start but with its first pose T_world_origin: the maps, the
  /// pose history, the velocity and the threshold's history are forgotten; the recent residuals (the scene's fit)
  /// are kept.
  void start_over(const SE3& T_world_origin);
  /// OdometryConfig::restart_after_lost failed or restart_after_suspect untrusted registrations in a row (not of
  /// voxel samples), and this frame has points.
  bool restart_due(const Frame& frame) const;
  /// Counts the frame (with features) towards restart_due when it was not trusted; a trusted one resets both counts,
  /// a registered one the lost count.
  void count_untrusted(const FrameResult& result);
  /// The constant-velocity prediction of the base at a centroid stamp (T_world_origin_ before any frame).
  SE3 predicted_centroid_pose(double centroid_stamp) const;
  /// Keeps the last two centroid poses, counts the map's frames and, for a `registered` pose (not a lost frame's
  /// prediction; a map's first frame is registered), measures the velocity from the anchor to it.
  void push_centroid_pose(const StampedPose& pose, bool registered);

  OdometryConfig config_;
  std::vector<LidarSetup> lidars_;
  std::vector<FrontEndWorkspace> workspaces_;
  std::vector<LidarFeatures> features_;
  LidarFeatures frame_features_;  ///< all LiDARs' features of the current frame
  LidarFeatures first_features_;  ///< the first frame's, kept until the second frame
  std::vector<FeatureBlock> frame_blocks_, first_blocks_;
  std::vector<PointCovariance> edge_covariances_, plane_covariances_;  ///< of frame_features_, base frame (UA only)
  std::optional<QueryCovariances> query_covariances_;
  VoxelMap edge_map_;
  VoxelMap plane_map_;
  std::vector<StampedPose> centroid_poses_;  ///< T_world_base at the last two frames' time centroids
  StampedPose last_registered_;              ///< the last centroid pose not a prediction (velocity_anchor)
  BodyVelocity velocity_;                    ///< latest_velocity
  std::size_t segment_frames_ = 0;           ///< frames since the start (or the last start_over)
  SE3 T_world_origin_;                       ///< the first frame's centroid pose (identity; after start_over, a prediction)
  std::size_t lost_in_a_row_ = 0;            ///< frames with features lost since the last one registered
  std::size_t untrusted_in_a_row_ = 0;       ///< frames with features suspect or lost since the last one trusted
  bool failed_on_voxel_samples_ = false;     ///< the last untrusted registration's frame was mostly voxel samples
  bool last_frame_trusted_ = true;           ///< the last frame was trusted or a map's first (judge_degenerate)
  /// Mean |r| of the last registered (not lost) frames, each divided by its
  /// frame's residual_scale().
  ResidualHistory recent_residuals_;
  RegistrationConfig registration_;                                     ///< this frame's (frame_registration)
  double degeneracy_stamp_ = -std::numeric_limits<double>::infinity();  ///< when lambda was last evaluated
  bool degenerate_scene_ = false;
  bool selection_paused_ = false;
  double first_stamp_ = 0.0;
  double error_sq_sum_ = 0.0;
  std::size_t error_count_ = 0;
};

}  // namespace mlidar::slam
