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
//      (calib/extrinsic_candidates.hpp).
// The base's features are computed once per frame and shared by every target.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/calib/extrinsic_candidates.hpp"
#include "mlidar/core/types.hpp"
#include "mlidar/slam/frontend.hpp"
#include "mlidar/slam/scan_to_map.hpp"

namespace mlidar::pipelines {

struct RefineConfig {
  int frame_step = 5;                   ///< a candidate every this many frames
  int window = 3;                       ///< base local map: frames k - window .. k + window
  double overlap_voxel_m = 0.5;         ///< both scans subsampled to this before eq 3.13
  double overlap_radius_m = 2.0;        ///< eq 3.13's r
  double min_overlap = 0.05;            ///< eq 3.14: absolute floor on Omega
  double relative_overlap = 0.8;        ///< eq 3.14's 0.8, relative to the best frame's Omega
  double coarse_correspondence_m = 1.0; ///< first registration's residual gate
  double fine_correspondence_m = 0.3;   ///< second registration's residual gate
  double min_match_ratio = 0.3;         ///< registrations matching fewer features are dropped
  std::size_t min_candidates = 3;       ///< fewer successful registrations: too_few_candidates
  double map_voxel_m = 1.0;
  int map_points_per_voxel = 20;
  calib::CandidateSelection selection;
  slam::FrontEndConfig front_end;
  slam::RegistrationConfig registration;
};

/// One LiDAR's frames as the refinement reads them.
struct LidarFrames {
  std::string name;
  LidarModel model;
  std::filesystem::path folder;               ///< where the clouds are (named in errors)
  std::vector<std::filesystem::path> clouds;  ///< one per stamp
};

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
  SE3 start;                             ///< X0
  SE3 T_base_target;                     ///< refined (X0 when the verdict is not ok)
  std::vector<std::size_t> frames_tried;
  std::vector<double> overlaps;          ///< Omega per tried frame
  std::size_t frames_low_overlap = 0;
  std::size_t registrations_failed = 0;  ///< too few matches or degenerate
  std::vector<calib::ExtrinsicCandidate> candidates;
  calib::CandidateAverage average;       ///< valid when ok
};

/// The base's per-frame features in the world and subsampled scans, computed on first use.
class BaseLocalMaps {
 public:
  /// Throws InputError when base.clouds has fewer clouds than stamps.
  BaseLocalMaps(LidarFrames base, BaseTrajectory trajectory, RefineConfig config);

  const BaseTrajectory& trajectory() const { return trajectory_; }
  /// Velocity of the base at frame k from its poses (zero when its neighbours are lost).
  slam::BodyVelocity velocity(std::size_t k) const;
  /// Base scan k in the base frame, voxel-subsampled (for eq 3.13).
  const std::vector<Eigen::Vector3f>& overlap_points(std::size_t k);
  /// Edge and plane maps of the frames around k (lost frames left out).
  std::pair<slam::VoxelMap, slam::VoxelMap> local_maps(std::size_t k);

 private:
  const slam::LidarFeatures& world_features(std::size_t j);

  LidarFrames base_;
  BaseTrajectory trajectory_;
  RefineConfig config_;
  slam::FrontEndWorkspace workspace_;
  std::vector<std::optional<slam::LidarFeatures>> world_features_;
  std::vector<std::optional<std::vector<Eigen::Vector3f>>> overlap_points_;
};

/// Refines X0 = T_base_target_start for one target LiDAR (clouds paired by index with the base's).
RefineResult refine_against_base(BaseLocalMaps& base, const LidarFrames& target, const SE3& T_base_target_start,
                                 const RefineConfig& config);

}  // namespace mlidar::pipelines
