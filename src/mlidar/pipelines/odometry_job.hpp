#pragma once
// `mlidar odometry`: runs slam::Odometry over a dataset folder (io/dataset.hpp,
// all or some LiDARs with their initial extrinsics and models) or over a
// folder of single-LiDAR clouds (natural file order, stamps k * period), and
// writes the run folder, every file atomically:
//   trajectory.tum    T_world_base at each frame stamp
//   trajectory.kitti  the same poses, KITTI 3x4 rows
//   map.ply           the local plane and edge maps (voxel-downsampled)
//   metrics.json      per-stage seconds per frame (mean/p50/p95/max), points
//                     in/out, smallest eigenvalues and observability per
//                     frame, degenerate, retried and lost frame counts
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::pipelines {

struct OdometryJob {
  std::filesystem::path dataset;          ///< a dataset folder, or empty
  std::filesystem::path scans;            ///< a folder of clouds, or empty
  double period = 0.1;                    ///< seconds between clouds of `scans`
  std::vector<std::string> lidars;        ///< dataset LiDARs to use; empty = all
  int threads = 0;                        ///< 0 = TBB's default
  std::filesystem::path out;
};

struct OdometryJobSummary {
  std::size_t frames = 0;
  std::size_t degenerate_frames = 0;
  std::size_t lost_frames = 0;
  double mean_frame_seconds = 0.0;
  Trajectory trajectory;
};

/// Files sorted in natural order: digit runs compare as numbers ("full20" < "full100").
std::vector<std::filesystem::path> natural_sorted_clouds(const std::filesystem::path& folder);
bool natural_less(const std::string& a, const std::string& b);

/// One cloud (or none) per frame of a LiDAR's scan folder. With at least
/// `frames` clouds, the k-th in natural order is frame k (as `mlidar
/// odometry` reads them). With fewer, some scans are missing: then each file
/// stem must be its frame number (000123.pcd is frame 123, as the simulator
/// writes them), and a frame without a file has none. InputError otherwise
/// (a stem that is not a number below `frames`, or two files for one frame).
std::vector<std::optional<std::filesystem::path>> frame_clouds(const std::filesystem::path& folder, std::size_t frames);

/// Reads a cloud; keeps the per-point times relative to the frame stamp when
/// the file's t field holds them (the simulator's convention).
Scan load_dataset_scan(const std::filesystem::path& path, double frame_stamp);

/// UsageError for a bad combination of options; InputError for bad files.
OdometryJobSummary run_odometry_job(const OdometryJob& job, const std::function<void(int, int)>& progress = {});

}  // namespace mlidar::pipelines
