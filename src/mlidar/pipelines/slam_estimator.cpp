#include "mlidar/pipelines/slam_estimator.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "mlidar/calib/ground_up.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/pipelines/slam_track.hpp"
#include "mlidar/slam/calibration_window.hpp"

namespace mlidar::pipelines {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// The trusted LiDARs' scans at `stamp`; a missing one is an empty scan (it contributes no features).
Frame trusted_frame(double stamp, const std::vector<std::optional<Scan>>& scans, const std::vector<std::size_t>& trusted) {
  Frame frame{stamp, {}};
  for (const std::size_t j : trusted) {
    frame.scans.push_back(scans[j].value_or(Scan{}));
    if (!scans[j]) frame.scans.back().stamp = stamp;
  }
  return frame;
}

/// Xi_calib's autocorrelation floor: a window spans N + 1 frames, consecutive ones share N.
calib::ConvergenceConfig with_window_overlap(calib::ConvergenceConfig config, int window_size) {
  config.min_autocorrelation_time = window_size + 1.0;
  return config;
}

/// Base-frame features at the stamp, brought back into the LiDAR's frame.
slam::LidarFrameFeatures to_lidar_frame(const slam::LidarFeatures& base, const SE3& T_base_lidar) {
  const SE3 T_lidar_base = T_base_lidar.inverse();
  slam::LidarFrameFeatures out;
  out.edges.resize(base.edges.size());
  out.planes.resize(base.planes.size());
  transform_points(T_lidar_base, base.edges, out.edges);
  transform_points(T_lidar_base, base.planes, out.planes);
  return out;
}

}  // namespace

std::string_view to_string(LidarRole role) {
  switch (role) {
    case LidarRole::initializing: return "initializing";
    case LidarRole::calibrating: return "calibrating";
    case LidarRole::trusted: return "trusted";
  }
  return "unknown";
}

SlamEstimator::SlamEstimator(SlamConfig config, std::vector<slam::LidarSetup> lidars, ExtrinsicSource source)
    : config_(std::move(config)),
      source_(source),
      monitor_(std::vector<SE3>(lidars.size(), SE3::identity()), with_window_overlap(config_.convergence, config_.window.size)),
      shock_(lidars.size(), config_.shock) {
  if (lidars.empty()) throw std::invalid_argument("SlamEstimator: no LiDARs");
  for (std::size_t j = 0; j < lidars.size(); ++j) {
    const bool given = j > 0 && source != ExtrinsicSource::online;
    tracks_.push_back(std::make_unique<Track>(with_extrinsic(lidars[j], given ? lidars[j].T_base_lidar : SE3::identity()), config_.initialization));
    Track& track = *tracks_.back();
    track.report.name = track.setup.name;
    if (j == 0 || source == ExtrinsicSource::fixed) track.role = LidarRole::trusted;
    else if (source == ExtrinsicSource::refine) track.role = LidarRole::calibrating;
    else {
      track.T_g_lidar = SE3(lidars[j].T_base_lidar.rotation(), Vec3::Zero());
      track.own = std::make_unique<slam::Odometry>(config_.odometry, std::vector{with_extrinsic(track.setup, track.T_g_lidar)});
    }
  }
  odometry_ = std::make_unique<slam::Odometry>(config_.odometry, trusted_setups());
  if (config_.window.refine_odometry) pose_window_.emplace(config_);
}

SlamEstimator::~SlamEstimator() = default;

std::vector<slam::LidarSetup> SlamEstimator::trusted_setups() {
  trusted_.clear();
  std::vector<slam::LidarSetup> setups;
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    if (tracks_[j]->role != LidarRole::trusted) continue;
    trusted_.push_back(j);
    setups.push_back(tracks_[j]->setup);
  }
  return setups;
}

void SlamEstimator::run_trusted_odometry(double stamp, const std::vector<std::optional<Scan>>& scans, SlamFrame& out) {
  last_odometry_ = odometry_->process(trusted_frame(stamp, scans, trusted_));
  out.lost = last_odometry_.lost;
  out.T_world_base = last_odometry_.T_world_base;
}

void SlamEstimator::calibrate(std::size_t j, double stamp, const Scan& scan, std::size_t frame_index, SlamLidarFrame& out) {
  Track& track = *tracks_[j];
  // The scan is deskewed once the next frame's pose is known, with the
  // velocity over its own sweep (the previous frame's velocity, a frame late,
  // biased the extrinsic by centimetres under handheld motion).
  const SE3& T_world_base = last_odometry_.T_world_base;
  std::optional<Track::Pending> previous = std::exchange(track.pending, Track::Pending{scan, stamp, T_world_base});
  if (!previous || !(stamp > previous->stamp)) return;
  const slam::BodyVelocity velocity =
      slam::BodyVelocity::from_relative_pose(previous->T_world_base.inverse() * T_world_base, stamp - previous->stamp);
  slam::StageSeconds unused{};
  slam::run_front_end(previous->scan, previous->stamp, track.setup, velocity, config_.odometry.front_end, track.workspace, track.features, unused);
  track.window.push_back({to_lidar_frame(track.features, track.setup.T_base_lidar), previous->T_world_base});
  if (track.window.size() > static_cast<std::size_t>(config_.window.size + 1)) track.window.erase(track.window.begin());

  // Eq 4.21: the window's poses are fixed by the map; T_base_lidar_j is the variable.
  const slam::MapView map{odometry_->edge_map(), odometry_->plane_map(), config_.odometry.registration};
  slam::CalibrationWindowOptions options;
  options.huber_delta_m = config_.odometry.registration.huber_delta_m;
  options.settle_passes = config_.window.calibration_settle_passes;
  const slam::CalibrationWindowResult window = slam::solve_calibration_window(track.window, track.setup.T_base_lidar, map, options);
  if (!window.solved) return;
  out.mean_residual_m = window.fit.mean_residual_m();
  const calib::WindowVerdict verdict =
      monitor_.add_window(j, window.T_base_lidar, window.information, window.residual_variance_m2, window.settled);
  out.lambda_min = verdict.lambda_min;
  out.window_estimate = window.T_base_lidar;
  out.window_information = window.information;
  out.window_residual_variance_m2 = window.residual_variance_m2;
  out.window_step_m = window.last_step_m;
  out.window_step_deg = rad_to_deg(window.last_step_rad);
  out.window_settled = window.settled;
  out.accepted = verdict.accepted;
  track.report.weak = monitor_.lidar(j).weak;
  // A constrained window that had not settled still moves the next window's start (it would otherwise restart from here).
  if (verdict.constrained) track.setup.T_base_lidar = window.T_base_lidar;
  if (verdict.accepted) track.high_residual_windows = 0;
  track.report.accepted = monitor_.lidar(j).accepted.size();
  if (!verdict.converged_now) return;
  // Algorithm 1 lines 8-11: the mean of L_calib accepted estimates, covariance alpha Xi_calib.
  track.setup.T_base_lidar = monitor_.lidar(j).T_base_lidar;
  track.report.covariance = config_.window.extrinsic_covariance_scale * monitor_.lidar(j).covariance;
  track.report.covariance_parts = monitor_.lidar(j).covariance_parts;
  track.report.outliers = monitor_.lidar(j).outliers;
  track.report.converged_frame = frame_index;
  if (!track.report.first_converged_frame) track.report.first_converged_frame = frame_index;
  track.role = LidarRole::trusted;
  track.window.clear();
  track.pending.reset();
  shock_.reset(j);
  trusted_changed_ = true;
  out.role = track.role;
}

void SlamEstimator::restart_initialization(std::size_t j) {
  Track& track = *tracks_[j];
  track.role = LidarRole::initializing;
  track.hand_eye.reset();
  track.rotation_only_pairs = 0;
  monitor_.restart(j);
  track.recent.clear();
}

void SlamEstimator::make_untrusted(std::size_t j) {
  restart_initialization(j);
  Track& track = *tracks_[j];
  track.T_g_lidar = SE3(track.setup.T_base_lidar.rotation(), Vec3::Zero());
  track.own.reset();  // restarted at its next scan, with up from that scan's ground (restart_own_odometry)
  track.report.covariance.reset();
  track.report.covariance_parts.reset();
  ++track.report.restarts;
  trusted_changed_ = true;
}

void SlamEstimator::restart_own_odometry(std::size_t j, const Scan& scan) {
  Track& track = *tracks_[j];
  // After a shock the old extrinsic's up is off by up to the shock's tilt
  // (~14 deg in Table 4.6), beyond the ground segmentation's 10 deg: its own
  // odometry then drifted and the hand-eye kept 14 of ~110 pairs in 116
  // frames (rhd campus, seed 1). The ground plane of the scan near that up corrects it.
  const Vec3 prior_up = track.T_g_lidar.rotation().conjugate() * Vec3::UnitZ();
  if (const std::optional<Vec3> up = calib::ground_up(scan.points, prior_up))
    track.T_g_lidar = SE3(calib::align_up(track.T_g_lidar.rotation(), *up), Vec3::Zero());
  track.own = std::make_unique<slam::Odometry>(config_.odometry, std::vector{with_extrinsic(track.setup, track.T_g_lidar)});
}

void SlamEstimator::detect_shocks(std::size_t frame_index, SlamFrame& out) {
  // The registration's own residuals at its last linearisation (its gate is the
  // adaptive correspondence threshold): no second search of the map.
  std::vector<double> residual(tracks_.size(), std::numeric_limits<double>::quiet_NaN());
  const std::vector<double>& registered = last_odometry_.lidar_mean_residual_m;
  for (std::size_t i = 0; i < trusted_.size() && i < registered.size(); ++i) {
    const std::size_t j = trusted_[i];
    if (out.lidars[j].scan_missing || last_odometry_.lost) continue;
    residual[j] = registered[i];
    out.lidars[j].mean_residual_m = std::isfinite(residual[j]) ? residual[j] : -1.0;
  }
  for (const std::size_t j : shock_.update(residual)) {
    out.lidars[j].shock = true;
    tracks_[j]->report.shock_frames.push_back(frame_index);
    // The base defines the base frame: its trigger is reported, the others are not moved for it;
    // fixed extrinsics are given, so there a trigger is reported only.
    if (j != 0 && source_ == ExtrinsicSource::online && tracks_[j]->role == LidarRole::trusted) make_untrusted(j);
  }
}

SlamFrame SlamEstimator::process(double stamp, const std::vector<std::optional<Scan>>& scans) {
  if (scans.size() != tracks_.size()) throw std::invalid_argument("SlamEstimator::process: one scan (or nullopt) per LiDAR expected");
  const std::size_t k = frames_++;
  SlamFrame out;
  out.stamp = stamp;
  out.lidars.resize(tracks_.size());
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    out.lidars[j].scan_missing = !scans[j].has_value();
    if (!scans[j]) ++tracks_[j]->report.missing_frames;
  }
  auto start = Clock::now();
  run_trusted_odometry(stamp, scans, out);
  out.seconds.odometry = seconds_since(start);
  if (pose_window_) {
    start = Clock::now();
    if (const auto update = pose_window_->add(k, last_odometry_, *odometry_)) {
      out.T_world_base = update->latest.T_world_base;
      out.settled = update->settled;
    }
    out.seconds.window = seconds_since(start);
  }

  trusted_changed_ = false;
  for (std::size_t j = 1; j < tracks_.size(); ++j) {
    if (!scans[j]) {
      tracks_[j]->recent.clear();
      tracks_[j]->pending.reset();
      continue;
    }
    start = Clock::now();
    if (tracks_[j]->role == LidarRole::initializing) {
      if (!tracks_[j]->own) restart_own_odometry(j, *scans[j]);
      initialize(j, stamp, *scans[j], scans[0] ? &*scans[0] : nullptr, k, out.lidars[j]);
      out.seconds.initialization += seconds_since(start);
    } else if (tracks_[j]->role == LidarRole::calibrating && !last_odometry_.lost) {
      calibrate(j, stamp, *scans[j], k, out.lidars[j]);
      out.seconds.calibration += seconds_since(start);
    }
  }
  start = Clock::now();
  detect_shocks(k, out);
  check_reinitialization(k, out);
  out.seconds.shock = seconds_since(start);
  if (trusted_changed_) {
    odometry_->set_lidars(trusted_setups());  // from the next frame on; the map and world are kept
    out.trusted_changed = true;
  }
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    out.lidars[j].role = tracks_[j]->role;
    out.calibrating = out.calibrating || tracks_[j]->role != LidarRole::trusted;
  }
  return out;
}

std::vector<SlamLidarReport> SlamEstimator::lidar_reports() const {
  std::vector<SlamLidarReport> reports;
  for (const auto& track : tracks_) {
    reports.push_back(track->report);
    reports.back().role = track->role;
    reports.back().T_base_lidar = track->setup.T_base_lidar;
  }
  return reports;
}

std::vector<slam::WindowPose> SlamEstimator::unsettled_poses() const {
  return pose_window_ ? pose_window_->unsettled() : std::vector<slam::WindowPose>{};
}

std::vector<Eigen::Vector3f> SlamEstimator::map_points() const {
  std::vector<Eigen::Vector3f> points = odometry_->plane_map().points();
  const std::vector<Eigen::Vector3f> edges = odometry_->edge_map().points();
  points.insert(points.end(), edges.begin(), edges.end());
  return points;
}

}  // namespace mlidar::pipelines
