#include "mlidar/pipelines/slam_job.hpp"

#include <algorithm>
#include <chrono>
#include <numeric>

#include <tbb/global_control.h>

#include "mlidar/core/covariance.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/pipelines/base_frame.hpp"
#include "mlidar/pipelines/given_extrinsics.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"
#include "mlidar/pipelines/slam_metrics.hpp"

namespace mlidar::pipelines {
namespace {

/// The source's LiDARs in the estimator's order: base first, then by name.
std::vector<std::size_t> estimator_order(const io::FrameSource& source) {
  const auto& lidars = source.lidars();
  std::vector<std::size_t> order(lidars.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const std::size_t base = source.reference_index().value_or(0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if ((a == base) != (b == base)) return a == base;
    return lidars[a].name < lidars[b].name;
  });
  return order;
}

/// The map in the dataset's base frame B: p_B = T_B_R p_R, Sigma_B = R_BR Sigma_R R_BR^T.
MapCloud map_in_base(MapCloud map, const BaseFrame& frame) {
  if (frame.is_reference) return map;
  for (Eigen::Vector3f& p : map.points) p = frame.point_to_base(p);
  if (map.covariances) {
    const Mat3 R = frame.T_base_reference.rotation_matrix();
    for (io::UpperCovariance& c : *map.covariances) c = io::to_upper(R * io::to_matrix(c) * R.transpose());
  }
  return map;
}

/// --extrinsics FILE with a dataset: every LiDAR of the source in it, relative to the dataset's base frame. With a
/// bag the source already took the file's extrinsics (io/bag_frames.hpp); its covariances count when they are
/// relative to the frame the job estimates in.
std::optional<io::Extrinsics> given_extrinsics(const SlamJob& job, const io::FrameSource& source, const BaseFrame& frame) {
  if (!job.bag.empty()) {
    if (!job.bag_options.extrinsics || job.bag_options.extrinsics->base != frame.name) return std::nullopt;
    io::Extrinsics given = *job.bag_options.extrinsics;
    for (io::LidarExtrinsic& lidar : given.lidars)
      for (const io::SourceLidar& read : source.lidars())
        if (read.name == lidar.name && read.initial_extrinsic) lidar.T_base_lidar = *read.initial_extrinsic;
    return given;
  }
  if (job.extrinsics.empty()) return std::nullopt;
  return read_given_extrinsics(job.extrinsics, source, frame.name);
}

/// Eq 4.24's alpha Xi of a given extrinsic as the odometry uses it (left perturbation, reference LiDAR frame):
/// the file's covariance, else the configured prior; zero for the reference LiDAR itself.
Mat6 given_extrinsic_covariance(const std::optional<Mat6>& covariance_base, const SE3& T_reference_lidar, bool is_reference,
                                const BaseFrame& frame, const SlamConfig& config) {
  if (is_reference) return Mat6::Zero();
  const std::optional<Mat6> local = covariance_base ? std::optional(frame.covariance_to_reference(*covariance_base)) : std::nullopt;
  return extrinsic_doubt(local, T_reference_lidar, config);
}

/// The estimator's LiDARs, their given extrinsics (the dataset's or --extrinsics FILE's) relative to the reference LiDAR.
std::vector<slam::LidarSetup> estimator_setups(const io::FrameSource& source, const std::vector<std::size_t>& order, const BaseFrame& frame,
                                               const std::optional<io::Extrinsics>& given, const SlamConfig& config) {
  std::vector<slam::LidarSetup> setups;
  for (const std::size_t i : order) {
    const io::SourceLidar& lidar = source.lidars()[i];
    const io::LidarExtrinsic* from_file = given ? given->find(lidar.name) : nullptr;
    const SE3 T_base_lidar = from_file ? from_file->T_base_lidar : lidar.initial_extrinsic.value_or(frame.T_base_reference);
    const SE3 T_reference_lidar = frame.extrinsic_to_reference(T_base_lidar);
    const std::optional<Mat6> covariance = from_file ? from_file->covariance : std::nullopt;
    setups.push_back({lidar.name, lidar.model, T_reference_lidar,
                      given_extrinsic_covariance(covariance, T_reference_lidar, i == frame.reference, frame, config)});
  }
  return setups;
}

void write_extrinsics_file(const std::filesystem::path& path, const BaseFrame& frame, const std::vector<SlamLidarReport>& reports) {
  io::Extrinsics extrinsics;
  extrinsics.base = frame.name;
  for (const auto& report : reports) extrinsics.lidars.push_back({report.name, report.T_base_lidar, report.covariance});
  io::write_extrinsics(path, extrinsics);
}

/// A report from the reference LiDAR's frame into the base frame.
SlamLidarReport report_in_base(SlamLidarReport report, const BaseFrame& frame) {
  report.T_base_lidar = frame.extrinsic_to_base(report.T_base_lidar);
  report.given_T_base_lidar = frame.extrinsic_to_base(report.given_T_base_lidar);
  if (report.covariance) report.covariance = frame.covariance_to_base(*report.covariance);
  return report;
}

/// The records of every frame, in order.
struct SlamRun {
  bool stopped_at_disagreement = false;  ///< a given extrinsic disagreed with the map at the last frame
  std::vector<SlamFrame> frames;
  std::vector<double> load_seconds;
  std::vector<slam::WindowPose> revisions;  ///< the window's final estimates of earlier frames, in the order given
};

/// A given extrinsic that should have been calibrated from the first frame: found at this frame to disagree with
/// the map, calibrated from there (extrinsic_check.recalibrate), and not after an extrinsic shock of that LiDAR
/// (its mounting moved during the run: it was right before).
bool calibrate_from_the_start(const SlamEstimator& estimator, std::size_t j) {
  const std::optional<ExtrinsicDisagreement>& found = estimator.track(j).disagreement();
  return found && found->recalibrated && !found->after_shock && !found->from_first_frame;
}

/// With `stop_at_disagreement` the run ends at the first frame where calibrate_from_the_start holds for a LiDAR.
SlamRun run_frames(const io::FrameSource& source, const std::vector<std::size_t>& order, SlamEstimator& estimator, FrameGaps& gaps,
                   bool stop_at_disagreement, const std::function<void(int, int)>& progress) {
  SlamRun run;
  for (std::size_t k = 0; k < source.frames(); ++k) {
    const auto start = std::chrono::steady_clock::now();
    io::SourceFrame frame = source.read(k);
    std::vector<std::optional<Scan>> scans;
    for (const std::size_t i : order) scans.push_back(std::move(frame.scans[i]));
    gaps.add(frame.skipped);
    run.load_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    run.frames.push_back(estimator.process(frame.stamp, scans));
    if (const auto& settled = run.frames.back().settled) run.revisions.push_back(*settled);
    if (progress) progress(static_cast<int>(k + 1), static_cast<int>(source.frames()));
    const auto& lidars = run.frames.back().lidars;
    for (std::size_t j = 0; j < lidars.size() && stop_at_disagreement; ++j)
      run.stopped_at_disagreement = run.stopped_at_disagreement || (lidars[j].extrinsic_disagrees && calibrate_from_the_start(estimator, j));
    if (run.stopped_at_disagreement) return run;
  }
  const std::vector<slam::WindowPose> unsettled = estimator.unsettled_poses();
  run.revisions.insert(run.revisions.end(), unsettled.begin(), unsettled.end());
  return run;
}

/// T_world_base at every frame: the window's last revision of it where there is one, else the frame's own estimate.
Trajectory final_trajectory(const SlamRun& run, const BaseFrame& frame) {
  std::vector<const SE3*> pose(run.frames.size());
  for (std::size_t k = 0; k < run.frames.size(); ++k) pose[k] = &run.frames[k].T_world_base;
  for (const slam::WindowPose& revision : run.revisions) pose.at(revision.frame) = &revision.T_world_base;
  Trajectory trajectory;
  for (std::size_t k = 0; k < run.frames.size(); ++k) trajectory.poses.push_back({run.frames[k].stamp, frame.pose_to_base(*pose[k])});
  return trajectory;
}

/// Each frame's pose covariance in pose_covariance.txt's tangent at the written pose: the left perturbation
/// taken to the output base (T_w_B = C T_w_R C^-1 moves Exp(d) by Ad(C)), then to [t additive, r local].
std::vector<io::StampedCovariance> pose_covariances(const SlamRun& run, const BaseFrame& frame, const Trajectory& trajectory) {
  const Mat6 to_base = frame.is_reference ? Mat6(Mat6::Identity()) : frame.T_base_reference.adjoint();
  std::vector<io::StampedCovariance> out;
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    const Mat6 left = to_base * run.frames[k].pose_covariance * to_base.transpose();
    out.push_back({trajectory.poses[k].stamp, covariance_in_local_tangent(trajectory.poses[k].T_world_base, left)});
  }
  return out;
}

SlamJobSummary summarize(const SlamRun& run, const SlamEstimator& estimator, const std::vector<std::size_t>& order, const FrameGaps& gaps,
                         const SlamJob& job, const BaseFrame& frame) {
  SlamJobSummary summary;
  summary.frames = run.frames.size();
  summary.trajectory = final_trajectory(run, frame);
  summary.gaps = gaps.summary_lines();
  summary.base_failure = gaps.base_failure(job.max_base_gaps, frame.reference);
  const std::vector<SlamLidarReport> reports = estimator.lidar_reports(run.frames);
  summary.lidars.resize(reports.size());
  for (std::size_t e = 0; e < reports.size(); ++e) summary.lidars[order[e]] = report_in_base(reports[e], frame);
  for (std::size_t k = 0; k < run.frames.size(); ++k) {
    const auto& f = run.frames[k];
    summary.lost_frames += f.lost ? 1 : 0;
    summary.lost_at_end = f.lost ? summary.lost_at_end + 1 : 0;
    if (f.map_restarted) summary.map_restarts.push_back(k);
    if (f.suspect) summary.suspect_frames.push_back(k);
    const auto& s = f.seconds;
    summary.mean_frame_seconds +=
        (s.odometry + s.initialization + s.calibration + s.shock + s.window) / static_cast<double>(run.frames.size());
  }
  summary.map_restart_warning = map_restart_warning(summary.map_restarts, estimator.trusted_odometry().config());
  return summary;
}

}  // namespace

bool SlamJobSummary::all_converged() const {
  return std::all_of(lidars.begin(), lidars.end(), [](const SlamLidarReport& l) { return l.role == LidarRole::trusted; });
}

bool SlamJobSummary::extrinsic_disagreed() const {
  return std::any_of(lidars.begin(), lidars.end(), [](const SlamLidarReport& l) { return l.disagreement.has_value(); });
}

bool SlamJobSummary::trusted() const { return all_converged() && lost_frames == 0 && !base_failure && !extrinsic_disagreed(); }

SlamJobSummary run_slam_job(const SlamJob& job, const std::function<void(int, int)>& progress) {
  if (job.threads < 0) throw UsageError("--threads must be >= 0");
  const SlamConfig config = job.config.empty() ? SlamConfig{} : read_slam_config(job.config);
  const io::FrameSource source = open_frames(job.dataset, job.bag, job.bag_options);
  const std::vector<std::size_t> order = estimator_order(source);
  std::unique_ptr<tbb::global_control> threads;
  if (job.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(job.threads));

  const BaseFrame frame = base_frame(source);
  const std::optional<io::Extrinsics> given = given_extrinsics(job, source, frame);
  // A given extrinsic found to disagree with the map (extrinsic_check.recalibrate) is calibrated from the first frame
  // on in a run started again: the frames before the verdict used it as given (not after an extrinsic shock: that
  // one is calibrated from the verdict on).
  std::vector<std::optional<ExtrinsicDisagreement>> disagreed(order.size());
  std::unique_ptr<SlamEstimator> estimator;
  std::unique_ptr<FrameGaps> gaps;
  SlamRun run;
  do {
    estimator = std::make_unique<SlamEstimator>(config, estimator_setups(source, order, frame, given, config), job.calibrate, disagreed);
    gaps = std::make_unique<FrameGaps>(source);
    run = run_frames(source, order, *estimator, *gaps, config.extrinsic_check.recalibrate, progress);
    for (std::size_t j = 1; j < order.size(); ++j)
      if (calibrate_from_the_start(*estimator, j)) disagreed[j] = estimator->track(j).disagreement();
  } while (run.stopped_at_disagreement);
  SlamJobSummary summary = summarize(run, *estimator, order, *gaps, job, frame);
  std::filesystem::create_directories(job.out);
  io::write_tum(job.out / "trajectory.tum", summary.trajectory);
  io::write_kitti_poses(job.out / "trajectory.kitti", summary.trajectory);
  const std::vector<io::StampedCovariance> covariances = pose_covariances(run, frame, summary.trajectory);
  io::write_pose_covariances(job.out / "pose_covariance.txt", covariances);
  if (!covariances.empty()) summary.last_pose_covariance = covariances.back().covariance;
  write_extrinsics_file(job.out / "extrinsics.yaml", frame, summary.lidars);
  write_map_ply(job.out / "map.ply", map_in_base(map_cloud(estimator->trusted_odometry()), frame));
  nlohmann::json metrics = slam_metrics_json(run.frames, order, summary.lidars, run.load_seconds, to_string(job.calibrate));
  add_pose_covariance_traces(metrics, covariances);
  metrics["skipped_scans"] = gaps->json();
  metrics["convergence"] = {{"lambda_calib", config.convergence.lambda_calib}, {"accepted_needed", config.convergence.accepted_needed}};
  const std::string text = metrics.dump(2);
  io::write_atomically(job.out / "metrics.json", [&](std::ostream& out) { out << text << '\n'; });
  return summary;
}

}  // namespace mlidar::pipelines
