#include "mlidar/pipelines/odometry_job.hpp"

#include <algorithm>

#include <memory>

#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/pipelines/given_extrinsics.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"
#include "mlidar/pipelines/slam_config.hpp"
#include "mlidar/slam/map_consistency.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {
namespace {

io::FrameSource open_source(const OdometryJob& job) {
  const int inputs = (job.dataset.empty() ? 0 : 1) + (job.scans.empty() ? 0 : 1) + (job.bag.empty() ? 0 : 1);
  if (inputs != 1) throw UsageError("give exactly one of --dataset DIR, --scans FOLDER or --bag BAG");
  if (job.dataset.empty() && !job.lidars.empty()) throw UsageError("--lidars applies to --dataset only (with --bag, --topics picks them)");
  if (!job.scans.empty()) return io::FrameSource::scan_folder(job.scans, job.period, job.times, job.scan_model);
  if (!job.bag.empty()) return open_frames({}, job.bag, job.bag_options);
  return io::FrameSource::dataset(job.dataset, job.lidars);
}

/// The name the extrinsics are relative to: the dataset's base, else (a folder of clouds) its one LiDAR.
std::string base_name(const io::FrameSource& source) {
  return source.dataset_info() ? source.dataset_info()->base : source.lidars().front().name;
}

/// The input's LiDARs with their extrinsics (or --extrinsics FILE's); for uncertainty-aware mapping every LiDAR but
/// the base frame's own gets alpha times the given covariance, else the configured prior (eq 4.24).
std::vector<slam::LidarSetup> lidar_setups(const OdometryJob& job, const io::FrameSource& source, const SlamConfig& config) {
  const std::string base = base_name(source);
  std::optional<io::Extrinsics> given;
  if (!job.extrinsics.empty()) given = read_given_extrinsics(job.extrinsics, source, base);
  if (!job.bag.empty() && job.bag_options.extrinsics && job.bag_options.extrinsics->base == base) given = job.bag_options.extrinsics;
  std::vector<slam::LidarSetup> setups;
  for (const io::SourceLidar& lidar : source.lidars()) {
    const io::LidarExtrinsic* from_file = given ? given->find(lidar.name) : nullptr;
    const SE3 T_base_lidar = from_file && job.bag.empty() ? from_file->T_base_lidar : lidar.initial_extrinsic.value_or(SE3::identity());
    const std::optional<Mat6> covariance = from_file ? from_file->covariance : std::nullopt;
    setups.push_back(
        {lidar.name, lidar.model, T_base_lidar, lidar.name == base ? Mat6::Zero() : extrinsic_doubt(covariance, T_base_lidar, config)});
  }
  return setups;
}

/// The odometry's frame: a LiDAR without a scan contributes an empty one at the frame stamp.
Frame odometry_frame(const io::SourceFrame& source) {
  Frame frame{source.stamp, {}};
  for (const auto& scan : source.scans) {
    frame.scans.push_back(scan.value_or(Scan{}));
    if (!scan) frame.scans.back().stamp = source.stamp;
  }
  return frame;
}

/// For each LiDAR without a model: how its features were made, in words.
std::vector<std::string> front_end_lines(const std::vector<slam::FrameResult>& results, const std::vector<slam::LidarSetup>& lidars,
                                         bool recover_rows) {
  std::vector<std::string> lines;
  const std::string of_frames = " of " + std::to_string(results.size()) + " frames (";
  for (std::size_t i = 0; i < lidars.size(); ++i) {
    if (!lidars[i].model.vertical_angles_deg.empty()) continue;
    const FrontEndTally tally = front_end_tally(results, i);
    const auto median_rows = [](const std::vector<int>& rows) { return std::to_string(rows[rows.size() / 2]); };
    std::string line = "LiDAR '" + lidars[i].name + "' has no model: ";
    if (!tally.ring_channel_rows.empty())
      line += "rows from its ring channel in " + std::to_string(tally.ring_channel_rows.size()) + of_frames +
              median_rows(tally.ring_channel_rows) + " rings, angles measured from the points); ";
    if (!tally.recovered_rows.empty())
      line += "scan rows recovered from the elevations in " + std::to_string(tally.recovered_rows.size()) + of_frames +
              median_rows(tally.recovered_rows) + " rows, median), range-image features and voxel samples; ";
    const std::size_t fallback = tally.frames_from(slam::RowSource::kVoxelFallback);
    if (fallback > 0 && !recover_rows)
      line += "rows are not recovered (odometry.recover_rows: false): 0.5 m voxel samples served as plane features";
    else if (fallback > 0)
      line += std::to_string(fallback) +
              " frame(s) showed no scan rows (a solid-state scanner, or keyframes merged from sweeps taken while moving) and used 0.5 m "
              "voxel samples as plane features";
    else
      line += "no frame fell back to voxel samples";
    lines.push_back(line + " (metrics.json front_end)");
  }
  return lines;
}

/// Planar neighbourhoods the map test needs of a LiDAR, of its own and of the others', to judge it.
constexpr std::size_t kMapTestPlanes = 100;

/// Each LiDAR's given extrinsic but lidars[base]'s judged against the map over the frames' residuals
/// (calib::ExtrinsicCheck; lost frames left out).
std::vector<GivenExtrinsicDisagreement> check_given_extrinsics(const std::vector<slam::FrameResult>& results,
                                                               const std::vector<slam::LidarSetup>& lidars, std::size_t base,
                                                               const std::string& compared_with,
                                                               const calib::ExtrinsicCheckConfig& config) {
  std::vector<std::size_t> order{base};  // the check's LiDAR j is lidars[order[j]]
  for (std::size_t i = 0; i < lidars.size(); ++i)
    if (i != base) order.push_back(i);
  calib::ExtrinsicCheck check(lidars.size(), config);
  std::vector<bool> judged(lidars.size(), true);
  judged[0] = false;  // the base defines the frame
  std::vector<GivenExtrinsicDisagreement> found;
  for (std::size_t k = 0; k < results.size(); ++k) {
    const std::vector<double>& residual = results[k].lidar_mean_residual_m;
    if (results[k].lost() || residual.size() != lidars.size()) continue;
    std::vector<double> ordered;
    for (const std::size_t i : order) ordered.push_back(residual[i]);
    for (const std::size_t j : check.update(ordered, judged))
      found.push_back({lidars[order[j]].name, k, check.median_ratio(j).value_or(0.0), -1.0, compared_with});
  }
  return found;
}

/// The map test (slam/map_consistency.hpp) on the final map: each auxiliary LiDAR not judged yet whose points lie
/// map_ratio times farther from the others' planes than from its own (the map's sources are the odometry's order).
void add_map_disagreements(const slam::Odometry& odometry, const std::vector<slam::LidarSetup>& lidars, std::size_t base,
                           const GivenExtrinsicChecks& config, std::size_t frames, std::vector<GivenExtrinsicDisagreement>& found) {
  if (config.map_first_frames == 0 || frames == 0) return;
  const std::vector<slam::SourceConsistency> consistency = slam::map_consistency(odometry.plane_map(), lidars.size());
  for (std::size_t i = 0; i < consistency.size(); ++i) {
    const slam::SourceConsistency& c = consistency[i];
    const std::string& name = lidars.at(c.source).name;
    const bool judged = std::any_of(found.begin(), found.end(), [&](const GivenExtrinsicDisagreement& d) { return d.lidar == name; });
    const double ratio = slam::consistency_ratio(consistency, i);
    if (c.source == base || judged || c.self_planes < kMapTestPlanes || c.cross_planes < kMapTestPlanes || !(ratio > config.map_ratio))
      continue;
    found.push_back({name, frames - 1, -1.0, ratio, "the other LiDARs"});
  }
}

}  // namespace

OdometryJobSummary run_odometry_job(const OdometryJob& job, const std::function<void(int, int)>& progress) {
  if (job.threads < 0) throw UsageError("--threads must be >= 0");
  const SlamConfig slam_config = job.config.empty() ? SlamConfig{} : read_slam_config(job.config);
  const slam::OdometryConfig& config = slam_config.odometry;
  const io::FrameSource source = open_source(job);
  const std::vector<slam::LidarSetup> lidars = lidar_setups(job, source, slam_config);
  std::unique_ptr<tbb::global_control> threads;
  if (job.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(job.threads));
  std::filesystem::create_directories(job.out);

  slam::Odometry odometry(config, lidars);
  FrameGaps gaps(source);
  std::vector<slam::FrameResult> results;
  OdometryJobSummary summary;
  for (std::size_t k = 0; k < source.frames(); ++k) {
    const io::SourceFrame frame = source.read(k);
    gaps.add(frame.skipped);
    results.push_back(odometry.process(odometry_frame(frame)));
    summary.trajectory.poses.push_back({frame.stamp, results.back().T_world_base});
    if (progress) progress(static_cast<int>(k + 1), static_cast<int>(source.frames()));
  }
  summary.frames = results.size();
  for (std::size_t k = 0; k < results.size(); ++k) {
    const slam::FrameResult& r = results[k];
    summary.degenerate_frames += r.registration.degenerate ? 1 : 0;
    summary.lost_frames += r.lost() ? 1 : 0;
    summary.lost_at_end = r.lost() ? summary.lost_at_end + 1 : 0;
    if (r.map_restarted) summary.map_restarts.push_back(k);
    if (r.suspect()) summary.suspect_frames.push_back(k);
    for (const double s : r.seconds) summary.mean_frame_seconds += s / static_cast<double>(results.size());
  }
  summary.map_restart_warning = map_restart_warning(summary.map_restarts, config);
  summary.degenerate_directions = degenerate_direction_counts(results);
  summary.gaps = gaps.summary_lines();
  summary.front_end = front_end_lines(results, lidars, config.front_end.recover_rows);
  summary.base_failure = gaps.base_failure(job.max_base_gaps, source.reference_index());
  // lidars follows source.lidars(). The others are judged against the base LiDAR, or, where the base frame is no
  // LiDAR (a vehicle's), against the dataset's reference_lidar, as slam does: only extrinsics relative to one
  // another can disagree with a map.
  const std::optional<std::size_t> reference = source.reference_index();
  if (reference && slam_config.extrinsic_check.enabled()) {
    const std::string& reference_name = lidars[*reference].name;
    const std::string compared_with = reference_name == base_name(source) ? "the base" : "the reference LiDAR " + reference_name;
    summary.disagreements = check_given_extrinsics(results, lidars, *reference, compared_with, slam_config.extrinsic_check.residual);
    add_map_disagreements(odometry, lidars, *reference, slam_config.extrinsic_check, results.size(), summary.disagreements);
  }
  io::write_tum(job.out / "trajectory.tum", summary.trajectory);
  io::write_kitti_poses(job.out / "trajectory.kitti", summary.trajectory);
  write_map_ply(job.out / "map.ply", odometry);
  const std::vector<io::StampedCovariance> covariances = pose_covariances(results);
  io::write_pose_covariances(job.out / "pose_covariance.txt", covariances);
  if (!covariances.empty()) summary.last_pose_covariance = covariances.back().covariance;
  nlohmann::json metrics = odometry_metrics_json(results, lidars);
  add_pose_covariance_traces(metrics, covariances);
  metrics["skipped_scans"] = gaps.json();
  metrics["extrinsic_check"] = nlohmann::json::array();
  for (const GivenExtrinsicDisagreement& d : summary.disagreements)
    metrics["extrinsic_check"].push_back({{"lidar", d.lidar},
                                          {"disagreed_frame", d.frame},
                                          {"residual_ratio", d.residual_ratio > 0.0 ? nlohmann::json(d.residual_ratio) : nlohmann::json()},
                                          {"map_ratio", d.map_ratio > 0.0 ? nlohmann::json(d.map_ratio) : nlohmann::json()},
                                          {"compared_with", d.compared_with}});
  const std::string text = metrics.dump(2);
  io::write_atomically(job.out / "metrics.json", [&](std::ostream& out) { out << text << '\n'; });
  return summary;
}

}  // namespace mlidar::pipelines
