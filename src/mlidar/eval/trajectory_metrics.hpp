#pragma once
// Trajectory error metrics with the definitions of evo (ATE = APE, RPE) and
// the KITTI odometry devkit (evaluate_odometry.cpp). All functions take pose
// sequences already associated: gt[i] and est[i] belong to the same instant.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/eval/alignment.hpp"
#include "mlidar/eval/statistics.hpp"

namespace mlidar::eval {

/// Absolute trajectory error (evo APE): E_i = T_gt_i^-1 T_est_i;
/// translation |t_gt_i - t_est_i| (m), rotation angle(R_gt_i^T R_est_i) (deg).
struct AteResult {
  ErrorStats translation_m;
  ErrorStats rotation_deg;
  std::vector<double> translation_errors_m;  ///< one per pose, for plots
};
AteResult compute_ate(const std::vector<SE3>& gt, const std::vector<SE3>& est);

enum class DeltaUnit : std::uint8_t { kFrames, kMeters };
const char* delta_unit_name(DeltaUnit unit);  ///< "frames", "m"

/// Relative pose error (evo RPE, all_pairs = false): pairs (i, j) of
/// consecutive ids; ids every `delta` frames from 0, or (metres) the poses
/// where the ground-truth path since the previous id first reaches delta
/// (evo filter_pairs_by_path). E = (T_gt_i^-1 T_gt_j)^-1 (T_est_i^-1 T_est_j).
/// translation_percent = 100 |t(E)| / (ground-truth path length from i to j).
struct RpeResult {
  double delta = 1.0;
  DeltaUnit unit = DeltaUnit::kFrames;
  ErrorStats translation_m;
  ErrorStats translation_percent;
  ErrorStats rotation_deg;
};
RpeResult compute_rpe(const std::vector<SE3>& gt, const std::vector<SE3>& est, double delta, DeltaUnit unit);

/// KITTI odometry metric (devkit evaluate_odometry.cpp): every 10th frame
/// starts segments of 100, 200, ..., 800 m of ground-truth path; the segment
/// ends at the first frame farther along than the length; per segment the
/// relative-pose error is divided by the length; results are the mean over
/// all segments, and per length (the devkit's error-against-path-length
/// plots). Empty when the path is shorter than 100 m.
struct KittiLengthDrift {
  double length_m = 0.0;
  std::size_t segments = 0;
  double translation_percent = 0.0;
  double rotation_deg_per_100m = 0.0;
};
struct KittiOdometryResult {
  std::size_t segments = 0;
  double translation_percent = 0.0;         ///< mean t_err / length * 100
  double rotation_deg_per_100m = 0.0;       ///< mean r_err / length, in deg per 100 m
  std::vector<KittiLengthDrift> by_length;  ///< lengths with at least one segment, shortest first
};
std::optional<KittiOdometryResult> compute_kitti_odometry(const std::vector<SE3>& gt, const std::vector<SE3>& est);

struct TrajectoryEvalOptions {
  AlignMode align = AlignMode::kSe3;
  bool associate_by_index = false;  ///< KITTI files: pose i with pose i
  double max_dt = 0.01;             ///< seconds, time association
  double delta = 1.0;               ///< RPE step
  DeltaUnit delta_unit = DeltaUnit::kFrames;
};

struct TrajectoryReport {
  TrajectoryEvalOptions options;
  std::size_t gt_poses = 0;
  std::size_t est_poses = 0;
  Alignment alignment;
  std::vector<double> stamps;          ///< ground-truth stamps of the associated poses
  std::vector<SE3> gt;                 ///< associated ground-truth poses
  std::vector<SE3> est_aligned;        ///< associated estimated poses after alignment
  std::vector<SE3> est;                ///< the same before alignment
  std::vector<std::size_t> est_index;  ///< each one's index in the estimated trajectory
  AteResult ate;
  RpeResult rpe;  ///< on the aligned estimate (matters for sim3)
  std::optional<KittiOdometryResult> kitti;
};

/// Validates both trajectories (InputError naming gt_source / est_source),
/// associates, aligns, and computes ATE, RPE and the KITTI metric.
TrajectoryReport evaluate_trajectory(const Trajectory& gt, const Trajectory& est, const TrajectoryEvalOptions& options,
                                     const std::string& gt_source, const std::string& est_source);

}  // namespace mlidar::eval
