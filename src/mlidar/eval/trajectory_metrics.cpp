#include "mlidar/eval/trajectory_metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "mlidar/core/error.hpp"
#include "mlidar/eval/association.hpp"

namespace mlidar::eval {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

double rotation_angle_rad(const Quat& rotation) { return so3_log(rotation).norm(); }

/// dist[i] = ground-truth path length from pose 0 to pose i.
std::vector<double> path_distances(const std::vector<SE3>& poses) {
  std::vector<double> distances(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    distances[i] = distances[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  return distances;
}

/// evo filter_pairs_by_index / filter_pairs_by_path with all_pairs = false.
std::vector<std::size_t> rpe_ids(const std::vector<SE3>& gt, double delta, DeltaUnit unit) {
  std::vector<std::size_t> ids;
  if (unit == DeltaUnit::kFrames) {
    const auto step = static_cast<std::size_t>(std::max(1.0, std::round(delta)));
    for (std::size_t i = 0; i < gt.size(); i += step) ids.push_back(i);
    return ids;
  }
  double path_since_id = 0.0;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (i > 0) path_since_id += (gt[i].translation() - gt[i - 1].translation()).norm();
    if (path_since_id >= delta) {
      ids.push_back(i);
      path_since_id = 0.0;
    }
  }
  return ids;
}

std::vector<SE3> poses_at(const Trajectory& trajectory, const std::vector<std::size_t>& indices) {
  std::vector<SE3> poses(indices.size());
  for (std::size_t i = 0; i < indices.size(); ++i) poses[i] = trajectory.poses[indices[i]].T_world_base;
  return poses;
}

void validate_options(const TrajectoryEvalOptions& options) {
  if (!(options.max_dt >= 0.0) || !std::isfinite(options.max_dt))
    throw UsageError("--max-dt must be a finite number >= 0 (got " + std::to_string(options.max_dt) + ")");
  if (!(options.delta > 0.0) || !std::isfinite(options.delta))
    throw UsageError("--delta must be a finite number > 0 (got " + std::to_string(options.delta) + ")");
  if (options.delta_unit == DeltaUnit::kFrames && options.delta != std::round(options.delta))
    throw UsageError("--delta in frames must be a whole number (got " + std::to_string(options.delta) + ")");
}

}  // namespace

const char* delta_unit_name(DeltaUnit unit) { return unit == DeltaUnit::kFrames ? "frames" : "m"; }

AteResult compute_ate(const std::vector<SE3>& gt, const std::vector<SE3>& est) {
  AteResult result;
  result.translation_errors_m.resize(gt.size());
  std::vector<double> rotation_errors_deg(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    result.translation_errors_m[i] = (gt[i].translation() - est[i].translation()).norm();
    rotation_errors_deg[i] = kRadToDeg * rotation_angle_rad(gt[i].rotation().conjugate() * est[i].rotation());
  }
  result.translation_m = summarize(result.translation_errors_m);
  result.rotation_deg = summarize(std::move(rotation_errors_deg));
  return result;
}

RpeResult compute_rpe(const std::vector<SE3>& gt, const std::vector<SE3>& est, double delta, DeltaUnit unit) {
  RpeResult result;
  result.delta = delta;
  result.unit = unit;
  const std::vector<std::size_t> ids = rpe_ids(gt, delta, unit);
  const std::vector<double> distances = path_distances(gt);
  std::vector<double> translation_m;
  std::vector<double> translation_percent;
  std::vector<double> rotation_deg;
  for (std::size_t k = 0; k + 1 < ids.size(); ++k) {
    const std::size_t i = ids[k];
    const std::size_t j = ids[k + 1];
    const SE3 error = (gt[i].inverse() * gt[j]).inverse() * (est[i].inverse() * est[j]);
    const double translation_error = error.translation().norm();
    translation_m.push_back(translation_error);
    rotation_deg.push_back(kRadToDeg * rotation_angle_rad(error.rotation()));
    const double path = distances[j] - distances[i];
    if (path > 0.0) translation_percent.push_back(100.0 * translation_error / path);
  }
  result.translation_m = summarize(std::move(translation_m));
  result.translation_percent = summarize(std::move(translation_percent));
  result.rotation_deg = summarize(std::move(rotation_deg));
  return result;
}

std::optional<KittiOdometryResult> compute_kitti_odometry(const std::vector<SE3>& gt, const std::vector<SE3>& est) {
  constexpr std::array<double, 8> kLengths = {100, 200, 300, 400, 500, 600, 700, 800};
  constexpr std::size_t kStepFrames = 10;
  const std::vector<double> distances = path_distances(gt);
  std::array<KittiLengthDrift, kLengths.size()> sums{};  // sums of t_err / length and r_err / length (rad/m)
  for (std::size_t first = 0; first < gt.size(); first += kStepFrames) {
    for (std::size_t k = 0; k < kLengths.size(); ++k) {
      const double length = kLengths[k];
      // devkit lastFrameFromSegmentLength: first frame with dist > dist[first] + length
      const auto it = std::upper_bound(distances.begin() + static_cast<std::ptrdiff_t>(first), distances.end(), distances[first] + length);
      if (it == distances.end()) continue;
      const auto last = static_cast<std::size_t>(it - distances.begin());
      const SE3 delta_gt = gt[first].inverse() * gt[last];
      const SE3 delta_est = est[first].inverse() * est[last];
      const SE3 error = delta_est.inverse() * delta_gt;
      sums[k].translation_percent += error.translation().norm() / length;
      sums[k].rotation_deg_per_100m += rotation_angle_rad(error.rotation()) / length;
      ++sums[k].segments;
    }
  }
  KittiOdometryResult result;
  double sum_translation = 0.0, sum_rotation = 0.0;
  for (std::size_t k = 0; k < kLengths.size(); ++k) {
    const KittiLengthDrift& sum = sums[k];
    if (sum.segments == 0) continue;
    result.segments += sum.segments;
    sum_translation += sum.translation_percent;
    sum_rotation += sum.rotation_deg_per_100m;
    const auto n = static_cast<double>(sum.segments);
    result.by_length.push_back(
        {kLengths[k], sum.segments, 100.0 * sum.translation_percent / n, 100.0 * kRadToDeg * sum.rotation_deg_per_100m / n});
  }
  if (result.segments == 0) return std::nullopt;
  result.translation_percent = 100.0 * sum_translation / static_cast<double>(result.segments);
  result.rotation_deg_per_100m = 100.0 * kRadToDeg * sum_rotation / static_cast<double>(result.segments);
  return result;
}

TrajectoryReport evaluate_trajectory(const Trajectory& gt, const Trajectory& est, const TrajectoryEvalOptions& options,
                                     const std::string& gt_source, const std::string& est_source) {
  validate_options(options);
  validate_trajectory(gt, gt_source);
  validate_trajectory(est, est_source);
  const Association association =
      options.associate_by_index ? associate_by_index(gt, est, est_source) : associate_by_time(gt, est, options.max_dt, est_source);
  TrajectoryReport report;
  report.options = options;
  report.gt_poses = gt.size();
  report.est_poses = est.size();
  report.gt = poses_at(gt, association.gt);
  const std::vector<SE3> est_raw = poses_at(est, association.est);
  report.est = est_raw;
  report.est_index = association.est;
  report.stamps.resize(association.size());
  for (std::size_t i = 0; i < association.size(); ++i) report.stamps[i] = gt.poses[association.gt[i]].stamp;
  report.alignment = compute_alignment(options.align, report.gt, est_raw, est_source);
  report.est_aligned.resize(est_raw.size());
  for (std::size_t i = 0; i < est_raw.size(); ++i) report.est_aligned[i] = report.alignment.apply(est_raw[i]);
  report.ate = compute_ate(report.gt, report.est_aligned);
  report.rpe = compute_rpe(report.gt, report.est_aligned, options.delta, options.delta_unit);
  report.kitti = compute_kitti_odometry(report.gt, report.est_aligned);
  return report;
}

}  // namespace mlidar::eval
