#include "mlidar/pipelines/slam_job.hpp"

#include <algorithm>
#include <chrono>
#include <numeric>

#include <tbb/global_control.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/pipelines/odometry_job.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"
#include "mlidar/pipelines/slam_metrics.hpp"

namespace mlidar::pipelines {
namespace {

/// The dataset's LiDARs in the estimator's order (base first, then by name) and their clouds per frame.
struct SlamInputs {
  io::Dataset dataset;
  std::vector<std::size_t> order;  ///< estimator index -> dataset index
  std::vector<slam::LidarSetup> lidars;  ///< estimator order
  std::vector<double> stamps;
  std::vector<std::vector<std::optional<std::filesystem::path>>> clouds;  ///< [estimator lidar][frame]
};

SlamInputs read_inputs(const std::filesystem::path& folder) {
  SlamInputs in;
  in.dataset = io::read_dataset_yaml(folder);
  in.stamps = io::read_times(folder / in.dataset.times);
  const auto& lidars = in.dataset.lidars;
  in.order.resize(lidars.size());
  std::iota(in.order.begin(), in.order.end(), std::size_t{0});
  const auto is_base = [&](std::size_t i) { return lidars[i].name == in.dataset.base; };
  const bool base_listed = std::any_of(in.order.begin(), in.order.end(), is_base);
  std::sort(in.order.begin(), in.order.end(), [&](std::size_t a, std::size_t b) {
    if (base_listed && is_base(a) != is_base(b)) return is_base(a);
    if (!base_listed && (a == 0) != (b == 0)) return a == 0;
    return lidars[a].name < lidars[b].name;
  });
  for (const std::size_t i : in.order) {
    in.lidars.push_back({lidars[i].name, lidars[i].model, lidars[i].initial_extrinsic.value_or(SE3::identity())});
    in.clouds.push_back(frame_clouds(folder / lidars[i].scans, in.stamps.size()));
  }
  return in;
}

std::vector<std::optional<Scan>> load_frame(const SlamInputs& in, std::size_t k) {
  std::vector<std::optional<Scan>> scans;
  for (const auto& clouds : in.clouds) {
    if (clouds[k]) scans.push_back(load_dataset_scan(*clouds[k], in.stamps[k]));
    else scans.emplace_back();
  }
  return scans;
}

void write_extrinsics_file(const std::filesystem::path& path, const SlamInputs& in, const std::vector<SlamLidarReport>& reports) {
  io::Extrinsics extrinsics;
  extrinsics.base = in.dataset.base;
  for (const auto& report : reports) extrinsics.lidars.push_back({report.name, report.T_base_lidar, report.covariance});
  io::write_extrinsics(path, extrinsics);
}

}  // namespace

bool SlamJobSummary::all_converged() const {
  return std::all_of(lidars.begin(), lidars.end(), [](const SlamLidarReport& l) { return l.role == LidarRole::trusted; });
}

SlamJobSummary run_slam_job(const SlamJob& job, const std::function<void(int, int)>& progress) {
  if (job.calibrate != "online" && job.calibrate != "refine" && job.calibrate != "fixed")
    throw UsageError("--calibrate must be online, refine or fixed, not '" + job.calibrate + "'");
  if (job.threads < 0) throw UsageError("--threads must be >= 0");
  if (job.dataset.empty()) throw UsageError("--dataset DIR is required");
  const SlamConfig config = job.config.empty() ? SlamConfig{} : read_slam_config(job.config);
  const SlamInputs in = read_inputs(job.dataset);
  std::unique_ptr<tbb::global_control> threads;
  if (job.threads > 0) threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(job.threads));

  const ExtrinsicSource source = job.calibrate == "online"   ? ExtrinsicSource::online
                                : job.calibrate == "refine" ? ExtrinsicSource::refine
                                                            : ExtrinsicSource::fixed;
  SlamEstimator estimator(config, in.lidars, source);
  std::vector<SlamFrame> frames;
  std::vector<double> load_seconds;
  for (std::size_t k = 0; k < in.stamps.size(); ++k) {
    const auto start = std::chrono::steady_clock::now();
    const auto scans = load_frame(in, k);
    load_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    frames.push_back(estimator.process(in.stamps[k], scans));
    if (const auto& settled = frames.back().settled) frames.at(settled->frame).T_world_base = settled->T_world_base;
    if (progress) progress(static_cast<int>(k + 1), static_cast<int>(in.stamps.size()));
  }

  for (const slam::WindowPose& pose : estimator.unsettled_poses()) frames.at(pose.frame).T_world_base = pose.T_world_base;
  SlamJobSummary summary;
  summary.frames = frames.size();
  const std::vector<SlamLidarReport> reports = estimator.lidar_reports();
  summary.lidars.resize(reports.size());
  for (std::size_t e = 0; e < reports.size(); ++e) summary.lidars[in.order[e]] = reports[e];
  for (const auto& f : frames) {
    summary.trajectory.poses.push_back({f.stamp, f.T_world_base});
    summary.lost_frames += f.lost ? 1 : 0;
    const auto& s = f.seconds;
    summary.mean_frame_seconds += (s.odometry + s.initialization + s.calibration + s.shock + s.window) / static_cast<double>(frames.size());
  }
  std::filesystem::create_directories(job.out);
  io::write_tum(job.out / "trajectory.tum", summary.trajectory);
  io::write_kitti_poses(job.out / "trajectory.kitti", summary.trajectory);
  write_extrinsics_file(job.out / "extrinsics.yaml", in, summary.lidars);
  write_map_ply(job.out / "map.ply", estimator.map_points());
  const std::string metrics = slam_metrics_json(frames, in.order, summary.lidars, load_seconds, job.calibrate).dump(2);
  io::write_atomically(job.out / "metrics.json", [&](std::ostream& out) { out << metrics << '\n'; });
  return summary;
}

}  // namespace mlidar::pipelines
