#pragma once
// `mlidar slam`: the M-LOAM estimator (slam_estimator.hpp) over a dataset
// folder (io/frame_source.hpp). The LiDARs run base first (the dataset's
// base), then by name, so the order the
// dataset lists them in does not matter. Online (default), the estimate does
// not start from the dataset's extrinsics (their rotations only tell each
// LiDAR's own odometry which way is up): every auxiliary LiDAR is
// initialized and calibrated online; refine calibrates starting from them (no hand-eye:
// the way under planar motion); fixed uses them as given. A LiDAR's scan folder may
// lack some frames (io/cloud_files.hpp: files named by frame number), and a
// scan may be unusable (empty, all NaN); such a LiDAR is reported and the
// others carry on. Writes the run folder, created
// at the end, every file atomically:
//   trajectory.tum / trajectory.kitti   T_world_base at each stamp
//   extrinsics.yaml   every LiDAR (dataset order), with alpha Xi_calib as covariance once converged
//   map.ply           the last local map, world frame
//   metrics.json      see slam_metrics.hpp
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/pipelines/frame_gaps.hpp"
#include "mlidar/pipelines/slam_estimator.hpp"

namespace mlidar::pipelines {

struct SlamJob {
  std::filesystem::path bag;         ///< a bag instead of a dataset folder (io/bag_frames.hpp)
  io::BagSourceOptions bag_options;  ///< its topics, base, extrinsics, models
  std::filesystem::path dataset;
  std::filesystem::path config;  ///< mloam.yaml, or empty for the defaults (Table 4.2)
  /// extrinsics.yaml to use instead of the dataset's initial extrinsics (with --calibrate fixed or refine), its
  /// covariances the extrinsic doubt of uncertainty-aware mapping; empty: the dataset's.
  std::filesystem::path extrinsics;
  ExtrinsicSource calibrate = ExtrinsicSource::online;
  int threads = 0;                             ///< 0 = TBB's default
  double max_base_gaps = kDefaultMaxBaseGaps;  ///< share of frames the base LiDAR may lack a usable scan in
  std::filesystem::path out;
};

struct SlamJobSummary {
  std::size_t frames = 0;
  std::size_t lost_frames = 0;
  std::size_t lost_at_end = 0;              ///< lost frames in a row at the end of the run (the last pose a prediction)
  std::vector<std::size_t> map_restarts;    ///< frames that started a new local map after untrusted frames in a row
  std::string map_restart_warning;          ///< the terminal's words on them (empty: none)
  std::vector<std::size_t> suspect_frames;  ///< frame indices whose base pose is doubtful
  double mean_frame_seconds = 0.0;
  Trajectory trajectory;
  std::vector<SlamLidarReport> lidars;       ///< dataset order
  std::vector<std::string> gaps;             ///< per LiDAR with skipped or missing scans, in words
  std::optional<std::string> base_failure;   ///< the base LiDAR lacked too many frames (exit 1)
  Mat6 last_pose_covariance = Mat6::Zero();  ///< the last frame's, as pose_covariance.txt holds it
  bool all_converged() const;                ///< every LiDAR trusted at the end
  bool extrinsic_disagreed() const;          ///< some given extrinsic disagreed with the map (calib::ExtrinsicCheck)
  /// The result can be trusted (exit 0): every LiDAR converged, no frame lost, the base not missing, no given
  /// extrinsic that disagreed with the map.
  bool trusted() const;
};

/// UsageError for bad options; InputError for bad files (dataset, config).
/// `progress(done, total)` after each frame.
SlamJobSummary run_slam_job(const SlamJob& job, const std::function<void(int, int)>& progress = {});

}  // namespace mlidar::pipelines
