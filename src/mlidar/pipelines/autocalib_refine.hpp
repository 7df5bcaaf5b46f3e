#pragma once
// `mlidar calibrate auto`, stage "refine" (thesis 3.4.3, appearance-based
// refinement). For an auxiliary LiDAR and every `frame_step`-th frame k:
//   1. overlap filter (eq 3.13-3.14): Omega_k of the base scan and the target
//      scan moved by the starting extrinsic. The thesis keeps Omega_k > 0.8;
//      Omega depends on r, the ring patterns and the FOVs (the rhd rig's two
//      LiDARs, rolled 40 deg apart, reach 0.22-0.40 at r = 2 m, 0.56-0.75 at
//      r = 8 m), so the frames kept are those with
//      Omega_k > max(min_overlap, relative_overlap * max_k Omega_k): the 0.8
//      applies to the sequence's best overlap;
//   2. the base LiDAR's local map around k: its LOAM features of frames
//      k-window..k+window, deskewed by its own odometry's velocity and put into
//      the world by its own odometry poses T_world_base_j;
//   3. the target's features at k (deskewed with the base velocity carried to
//      the target by the starting extrinsic) registered point-to-plane /
//      point-to-line against that map (slam::register_scan_to_map, coarse
//      then fine gate) from T_world_base_k X0: the candidate
//      X_k = T_world_base_k^-1 T_world_target_k with its error and information;
//   4. the best candidates by registration error are averaged on SO(3) x R^3
//      (calib/extrinsic_candidates.hpp). Registrations degenerate along one
//      translation (a street seen by a bumper LiDAR) do not enter that mean;
//      when too few others succeed, all are fused by their information, which
//      observes every direction when the drive turned, registered again from
//      the fused estimate and fused once more.
// The base's features are computed once per frame and shared by every target;
// each cloud is parsed once in stage 1, except the target clouds of the frames
// that pass the overlap filter, read again for each registration (once more
// per fusion pass), and the search frames' (autocalib_search.hpp).
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/calib/extrinsic_candidates.hpp"
#include "mlidar/core/types.hpp"
#include "mlidar/slam/frontend.hpp"
#include "mlidar/slam/scan_to_map.hpp"

namespace mlidar::pipelines {

struct RefineConfig {
  int frame_step = 5;                    ///< a candidate every this many frames
  int window = 3;                        ///< base local map: frames k - window .. k + window
  double overlap_voxel_m = 0.5;          ///< both scans subsampled to this before eq 3.13
  double overlap_radius_m = 2.0;         ///< eq 3.13's r
  double min_overlap = 0.05;             ///< eq 3.14: absolute floor on Omega
  double relative_overlap = 0.8;         ///< eq 3.14's 0.8, relative to the best frame's Omega
  double coarse_correspondence_m = 1.0;  ///< first registration's residual gate
  double fine_correspondence_m = 0.3;    ///< second registration's residual gate
  double min_match_ratio = 0.3;          ///< registrations matching fewer features are dropped
  std::size_t min_candidates = 3;        ///< fewer successful registrations: too_few_candidates
  /// When fewer registrations than min_candidates fix the whole extrinsic, the degenerate ones are fused by their
  /// information (calib::fuse_by_information); the fusion is the answer only when its covariance is within these
  /// 1-sigma bounds (largest eigenvalue of each block): 2 sigma inside the 0.3 deg / 3 cm a calibration must reach.
  double max_fused_translation_sd_m = 0.015;
  double max_fused_rotation_sd_deg = 0.15;
  int fusion_passes = 1;  ///< registrations again from the fused estimate, each fused anew
  double map_voxel_m = 1.0;
  int map_points_per_voxel = 20;
  calib::CandidateSelection selection;
  slam::FrontEndConfig front_end;
  slam::RegistrationConfig registration;
};

/// One target LiDAR as the refinement reads it: the overlap subsamples, kept
/// while stage 1 read its clouds, and its scans, read again for the frames
/// that pass the overlap filter.
struct TargetFrames {
  std::string name;
  LidarModel model;
  /// Scan k voxel-subsampled (overlap_voxel_m) in its own frame at the candidate frames (k % frame_step == 0; empty elsewhere);
  /// nullopt: no scan there.
  std::vector<std::optional<std::vector<Eigen::Vector3f>>> overlap_points;
  std::function<std::optional<Scan>(std::size_t)> read_scan;  ///< frame k's scan, or nullopt
};

/// `scan` voxel-subsampled to `voxel_m` (one point per voxel, slam::voxel_subsample), in its own frame.
std::vector<Eigen::Vector3f> overlap_subsample(const Scan& scan, double voxel_m);

/// The base LiDAR's own odometry.
struct BaseTrajectory {
  std::vector<double> stamps;
  std::vector<SE3> T_world_base;
  std::vector<bool> lost;
};

enum class RefineVerdict { ok, no_overlap, too_few_candidates };
const char* to_string(RefineVerdict verdict);

struct RefineResult {
  RefineVerdict verdict = RefineVerdict::too_few_candidates;
  std::string message;
  SE3 start;          ///< X0
  SE3 T_base_target;  ///< refined (X0 when the verdict is not ok)
  std::vector<std::size_t> frames_tried;
  std::vector<double> overlaps;  ///< Omega per tried frame
  std::size_t frames_low_overlap = 0;
  std::size_t registrations_failed = 0;  ///< too few matches or degenerate
  std::vector<calib::ExtrinsicCandidate> candidates;
  calib::CandidateAverage average;  ///< valid when ok from the registrations that fixed the whole extrinsic
  /// Set when ok from degenerate registrations fused by information (then `average` is empty).
  std::optional<calib::InformationFusion> fusion;
  const Mat6& covariance() const { return fusion ? fusion->covariance : average.covariance; }
};

/// The base's per-frame features in the world and subsampled scans, built
/// while stage 1 reads the frames: add_pose for every frame in order, and
/// add_scan for frame k once the pose of k + 1 (or of the last frame) is in,
/// since the deskew velocity of k looks one frame ahead.
class BaseLocalMaps {
 public:
  BaseLocalMaps(std::string name, LidarModel model, RefineConfig config);

  void add_pose(double stamp, const SE3& T_world_base, bool lost);
  /// Scan k of the base (k < frames added): its features deskewed with velocity(k), put into the world, and at
  /// candidate frames its overlap subsample. Lost frames keep nothing.
  void add_scan(std::size_t k, const Scan& scan);

  const BaseTrajectory& trajectory() const { return trajectory_; }
  /// Velocity of the base at frame k from its poses (zero when its neighbours are lost).
  slam::BodyVelocity velocity(std::size_t k) const;
  /// Base scan k in the base frame, voxel-subsampled (for eq 3.13); empty when it had no scan.
  const std::vector<Eigen::Vector3f>& overlap_points(std::size_t k) const;
  /// Edge and plane maps of the frames around k (lost frames and frames without a scan left out).
  std::pair<slam::VoxelMap, slam::VoxelMap> local_maps(std::size_t k) const;
  /// The edge and plane features of frames k - window .. k + window in the base frame at k (same frames left out).
  std::vector<Eigen::Vector3f> local_points(std::size_t k, std::size_t window) const;

 private:
  std::string name_;
  LidarModel model_;
  BaseTrajectory trajectory_;
  RefineConfig config_;
  slam::FrontEndWorkspace workspace_;
  std::vector<std::optional<slam::LidarFeatures>> world_features_;
  std::vector<std::vector<Eigen::Vector3f>> overlap_points_;
};

/// Refines X0 = T_base_target_start for one target LiDAR (frames paired by index with the base's).
RefineResult refine_against_base(const BaseLocalMaps& base, const TargetFrames& target, const SE3& T_base_target_start,
                                 const RefineConfig& config);

}  // namespace mlidar::pipelines
