#pragma once
// Per-LiDAR front end: range image -> segmentation -> features -> deskew into
// the base frame at the frame stamp. A LiDAR without a vertical angle table
// (a folder of plain clouds) takes its rows from the scan's `ring` channel
// (angles from the points), or recovers them from the scan's elevations
// (row_recovery.hpp); where a scan shows no rows (a solid-state
// scanner) it falls back to a voxel subsample whose points all serve as
// plane queries (the matcher checks planarity in the map).
#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"
#include "mlidar/core/types.hpp"
#include "mlidar/slam/deskew.hpp"
#include "mlidar/slam/features.hpp"
#include "mlidar/slam/range_image.hpp"
#include "mlidar/slam/row_recovery.hpp"
#include "mlidar/slam/segmentation.hpp"

namespace mlidar::slam {

enum class Stage : std::uint8_t { kRangeImage, kSegmentation, kFeatures, kDeskew, kRegistration, kMapUpdate };
inline constexpr std::size_t kStageCount = 6;
const char* stage_name(Stage stage);  ///< "range_image", ...

/// Where a LiDAR's range-image rows came from in one frame.
enum class RowSource : std::uint8_t { kModel, kRingChannel, kRecovered, kVoxelFallback };
const char* row_source_name(RowSource source);  ///< "model", "ring_channel", "recovered", "voxel_fallback"

/// Seconds spent per stage (summed over LiDARs when they run one after another).
using StageSeconds = std::array<double, kStageCount>;

struct FrontEndConfig {
  SegmentationConfig segmentation;
  FeatureConfig features;
  double fallback_voxel_m = 0.5;  ///< subsample size for LiDARs without a model
  /// For LiDARs without a model: recover each scan's rows (on) or always use the voxel fallback.
  bool recover_rows = true;
  /// After a ring-less scan whose rows could not be recovered, the same LiDAR's next 1, then 2, 4, ... scans
  /// (doubling after each refusal, at most this many) take the voxel fallback without searching; a recovered scan
  /// resets it; 0: search every scan. A scanner whose clouds show no rows (solid-state, sweeps merged while moving)
  /// keeps showing none, and each refused search costs 10-20 ms of a 75k-point cloud: on real BALM keyframes 87 of
  /// 100 are refused, a third of the run (docs/benchmarks.md "A coarse pass before the full registration").
  int recover_rows_max_skip = 4;
  RowRecoveryConfig row_recovery;
};

/// One LiDAR as the odometry sees it.
struct LidarSetup {
  std::string name;
  LidarModel model;  ///< vertical_angles_deg may be empty (fallback)
  SE3 T_base_lidar;
  /// alpha Xi of T_base_lidar (eq 4.24): left perturbation, base frame, [t, r]; zero for the base or a certain one.
  /// Used by uncertainty-aware mapping only (OdometryConfig::uncertainty).
  Mat6 extrinsic_covariance = Mat6::Zero();
};

/// Features of one LiDAR in the base frame at the reference stamp given to run_front_end.
struct LidarFeatures {
  std::vector<Eigen::Vector3f> edges;
  std::vector<Eigen::Vector3f> planes;
  /// Capture times (seconds from the reference stamp) of each edge / plane;
  /// empty when the scan has no times. They let a later, better velocity
  /// deskew the features again.
  std::vector<float> edge_times;
  std::vector<float> plane_times;
  /// Rows of the range image the features came from: the model's rings, or
  /// those recovered from the scan; 0 when the voxel fallback made them.
  int rows = 0;
  RowSource row_source = RowSource::kModel;
  /// Of `planes`, how many are voxel samples rather than range-image planes
  /// (all with the fallback; with recovered rows the samples come after the planes).
  std::size_t voxel_samples = 0;
};

/// Buffers reused across frames (one per LiDAR, so LiDARs can run in parallel), and the row recovery's back-off
/// between one LiDAR's consecutive scans (FrontEndConfig::recover_rows_max_skip; a fresh workspace searches).
struct FrontEndWorkspace {
  RangeImage image;
  Segmentation segmentation;
  FeatureWorkspace features;
  FeatureIndices indices;
  std::vector<double> sorted_angles_deg;
  std::optional<RecoveredRows> recovered;
  int recovery_skips_left = 0;  ///< scans still to take the fallback without searching
  int recovery_next_skip = 1;   ///< scans to skip after the next refusal
};

/// Runs the front end; `velocity` deskews each point to the base at
/// `reference_stamp` by its time from it (scan.time counts from scan.stamp,
/// so the shift is scan.stamp - reference_stamp).
void run_front_end(const Scan& scan, double reference_stamp, const LidarSetup& lidar, const BodyVelocity& velocity,
                   const FrontEndConfig& config, FrontEndWorkspace& workspace, LidarFeatures& out, StageSeconds& seconds);

/// Indices of the first point in each voxel of size voxel_m (finite points only).
std::vector<std::uint32_t> voxel_subsample(std::span<const Eigen::Vector3f> points, double voxel_m);

}  // namespace mlidar::slam
