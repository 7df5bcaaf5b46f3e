#pragma once
// `mlidar odometry`: runs slam::Odometry over the frames of an io::FrameSource
// (a dataset folder: all or some LiDARs with their initial extrinsics and
// models; or a folder of single-LiDAR clouds: natural file order, stamps k *
// period), and writes the run folder, every file atomically:
//   trajectory.tum    T_world_base at each frame stamp
//   trajectory.kitti  the same poses, KITTI 3x4 rows
//   map.ply           the local plane and edge maps (voxel-downsampled)
//   metrics.json      per-stage seconds per frame (mean/p50/p95/max), points
//                     in/out, smallest eigenvalues and observability per
//                     frame, degenerate, retried and lost frame counts,
//                     skipped_scans (frame_gaps.hpp), front_end (per LiDAR:
//                     frames whose rows came from the model, were recovered
//                     from the scan, or fell back to voxel samples)
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/pipelines/frame_gaps.hpp"

namespace mlidar::pipelines {

struct OdometryJob {
  std::filesystem::path bag;                   ///< a bag instead of a dataset folder (io/bag_frames.hpp)
  io::BagSourceOptions bag_options;            ///< its topics, base, extrinsics, models
  std::filesystem::path dataset;               ///< a dataset folder, or empty
  std::filesystem::path scans;                 ///< a folder of clouds, or empty
  double period = 0.1;                         ///< seconds between clouds of `scans`
  std::optional<std::filesystem::path> times;  ///< instead of `period`: one stamp per cloud of `scans`
  LidarModel scan_model;                       ///< the LiDAR of `scans` (`--model`); empty: rows recovered or voxels
  std::vector<std::string> lidars;             ///< dataset LiDARs to use; empty = all
  int threads = 0;                             ///< 0 = TBB's default
  double max_base_gaps = kDefaultMaxBaseGaps;  ///< share of frames the base LiDAR may lack a usable scan in
  /// `--config`: the same YAML as `mlidar slam --config` (slam_config.hpp);
  /// odometry reads its `odometry` and `selection` sections. Empty: defaults.
  std::filesystem::path config;
  /// `--extrinsics FILE` with a dataset or clouds: every LiDAR's extrinsic instead of the input's, with the
  /// covariance that uncertainty-aware mapping gives it (a bag's are in bag_options). Empty: the input's.
  std::filesystem::path extrinsics;
  std::filesystem::path out;
};

/// A given extrinsic that disagreed with the map (calib::ExtrinsicCheck): the odometry used it as given.
struct GivenExtrinsicDisagreement {
  std::string lidar;
  std::size_t frame = 0;        ///< the frame the median ratio crossed the limit (the last frame: the map test)
  double residual_ratio = 0.0;  ///< that median of the LiDAR's residual over the base's (-1: judged by the map test)
  double map_ratio = -1.0;      ///< the map test's ratio on the final map (slam/map_consistency.hpp; -1: not judged by it)
  /// What it was compared with, in words: "the base" or, where the base frame is no LiDAR (a vehicle's), "the
  /// reference LiDAR NAME" (dataset.yaml reference_lidar) for the residual ratio; "the other LiDARs" for the map test.
  std::string compared_with = "the base";
};

struct OdometryJobSummary {
  std::size_t frames = 0;
  std::size_t degenerate_frames = 0;
  /// Of those, how many had their weak translation closest to each base axis (base_axis_words), most first.
  std::vector<std::pair<std::string, std::size_t>> degenerate_directions;
  std::size_t lost_frames = 0;
  std::size_t lost_at_end = 0;              ///< lost frames in a row at the end of the run (the last pose a prediction)
  std::vector<std::size_t> map_restarts;    ///< frames that started a new local map after untrusted frames in a row
  std::string map_restart_warning;          ///< the terminal's words on them (empty: none)
  std::vector<std::size_t> suspect_frames;  ///< frame indices whose pose is doubtful (FrameResult::suspect)
  double mean_frame_seconds = 0.0;
  Trajectory trajectory;
  std::vector<std::string> gaps;             ///< per LiDAR with skipped or missing scans, in words
  std::vector<std::string> front_end;        ///< per LiDAR without a model: rows recovered or voxel samples, in words
  std::optional<std::string> base_failure;   ///< the base LiDAR lacked too many frames (exit 1)
  Mat6 last_pose_covariance = Mat6::Zero();  ///< the last frame's, as pose_covariance.txt holds it
  std::vector<GivenExtrinsicDisagreement> disagreements;
  /// The result can be trusted (exit 0): no frame lost, the base not missing, no given extrinsic that disagreed.
  bool trusted() const { return lost_frames == 0 && !base_failure && disagreements.empty(); }
};

/// UsageError for a bad combination of options; InputError for bad files.
OdometryJobSummary run_odometry_job(const OdometryJob& job, const std::function<void(int, int)>& progress = {});

}  // namespace mlidar::pipelines
