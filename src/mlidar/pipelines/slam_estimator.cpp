#include "mlidar/pipelines/slam_estimator.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <utility>

#include "mlidar/slam/calibration_window.hpp"

namespace mlidar::pipelines {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// Correspondence gates (m) of the calibration's re-matching passes: the
/// hand-eye start may be a degree and centimetres off (0.5 m at 30 m range),
/// the second pass matches at the first pass's solution.
constexpr std::array<double, 2> kCalibrationGatesM = {1.0, 0.3};
/// Frames between the two ends of a motion pair (eq 4.13 pairs consecutive
/// frames). Measured on the simulated rhd handheld drive (80 frames, 10 Hz):
/// with consecutive frames sigma_min2 of Q_K reached only 0.13 < sigma_R =
/// 0.25 (rotations of 1-3 deg per frame); pairs 5 frames apart (overlapping,
/// one per frame) rotate 5x more.
constexpr std::size_t kPairStride = 5;

/// The trusted LiDARs' scans at `stamp`; a missing one is an empty scan (it contributes no features).
Frame trusted_frame(double stamp, const std::vector<std::optional<Scan>>& scans, const std::vector<std::size_t>& trusted) {
  Frame frame{stamp, {}};
  for (const std::size_t j : trusted) {
    frame.scans.push_back(scans[j].value_or(Scan{}));
    if (!scans[j]) frame.scans.back().stamp = stamp;
  }
  return frame;
}

slam::LidarSetup with_extrinsic(slam::LidarSetup setup, const SE3& T_base_lidar) {
  setup.T_base_lidar = T_base_lidar;
  return setup;
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

/// One LiDAR's state across frames.
struct SlamEstimator::Track {
  slam::LidarSetup setup;  ///< T_base_lidar: the current extrinsic
  LidarRole role = LidarRole::initializing;
  calib::OnlineHandEye hand_eye;
  std::unique_ptr<slam::Odometry> own;      ///< its own odometry while initializing
  /// T_g_lidar: the frame g the own odometry runs in is the LiDAR's rotated by
  /// the given extrinsic's rotation (identity when none is given), so that its
  /// ground segmentation knows which way is up (with identity, a LiDAR rolled
  /// 40 deg lost every frame on 2 of 10 seeds); B_k is taken back to the LiDAR
  /// frame, so the hand-eye does not depend on it.
  SE3 T_g_lidar;
  struct PosePair {
    SE3 T_world_lidar;  ///< own odometry
    SE3 T_world_base;   ///< trusted odometry, same frame
  };
  std::deque<PosePair> recent;              ///< the last kPairStride + 1 frames, without gaps
  std::vector<slam::CalibrationFrame> window;  ///< the last N + 1 frames while calibrating
  struct Pending {
    Scan scan;
    double stamp = 0.0;
    SE3 T_world_base;
  };
  std::optional<Pending> pending;  ///< while calibrating: the last scan, deskewed at the next frame
  slam::FrontEndWorkspace workspace;
  slam::LidarFeatures features;
  SlamLidarReport report;

  Track(slam::LidarSetup lidar, calib::OnlineHandEyeConfig config) : setup(std::move(lidar)), hand_eye(config) {}
};

SlamEstimator::SlamEstimator(SlamConfig config, std::vector<slam::LidarSetup> lidars, ExtrinsicSource source)
    : config_(std::move(config)),
      source_(source),
      monitor_(std::vector<SE3>(lidars.size(), SE3::identity()), config_.convergence),
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

void SlamEstimator::initialize(std::size_t j, double stamp, const Scan& scan, std::size_t frame_index, SlamLidarFrame& out) {
  Track& track = *tracks_[j];
  const slam::FrameResult own = track.own->process(Frame{stamp, {scan}});
  const SE3 T_world_lidar = own.T_world_base * track.T_g_lidar;
  const SE3& T_world_base = last_odometry_.T_world_base;
  if (own.lost || last_odometry_.lost) {
    track.recent.clear();  // no motion pair across a frame that did not register
    return;
  }
  track.recent.push_back({T_world_lidar, T_world_base});
  if (track.recent.size() > kPairStride) {
    // Eq 4.13 over kPairStride frames: A = T_{b_{k-s} b_k}, B = T_{l_{k-s} l_k}.
    const auto& from = track.recent.front();
    const calib::MotionPair pair{from.T_world_base.inverse() * T_world_base, from.T_world_lidar.inverse() * T_world_lidar};
    track.recent.pop_front();
    // Eq 3.4: both motions of a rigid rig share the screw angle and pitch; a pair
    // that does not (an odometry error) is kept out (measured: 26 of 75 on rhd handheld).
    if (calib::screw_residual(pair, calib::HandEyeConfig{}).inlier) track.hand_eye.add(pair);
  }
  track.report.initialization = track.hand_eye.status();
  if (track.hand_eye.status().state != calib::OnlineHandEyeState::ready) return;
  track.setup.T_base_lidar = track.hand_eye.status().T_base_lidar;
  track.role = LidarRole::calibrating;
  track.report.initialized_frame = frame_index;
  track.own.reset();
  out.role = track.role;
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
  const slam::CalibrationWindowResult window =
      slam::solve_calibration_window(track.window, track.setup.T_base_lidar, map, kCalibrationGatesM, config_.odometry.registration.huber_delta_m);
  if (!window.solved) return;
  out.mean_residual_m = window.fit.mean_residual_m();
  const calib::WindowVerdict verdict = monitor_.add_window(j, window.T_base_lidar, window.information);
  out.lambda_min = verdict.lambda_min;
  out.window_estimate = window.T_base_lidar;
  out.accepted = verdict.accepted;
  track.report.weak = monitor_.lidar(j).weak;
  if (verdict.accepted) track.setup.T_base_lidar = window.T_base_lidar;
  track.report.accepted = monitor_.lidar(j).accepted.size();
  if (!verdict.converged_now) return;
  // Algorithm 1 lines 8-11: the mean of L_calib accepted estimates, covariance alpha Xi_calib.
  track.setup.T_base_lidar = monitor_.lidar(j).T_base_lidar;
  track.report.covariance = config_.window.extrinsic_covariance_scale * monitor_.lidar(j).covariance;
  track.report.converged_frame = frame_index;
  track.role = LidarRole::trusted;
  track.window.clear();
  track.pending.reset();
  shock_.reset(j);
  trusted_changed_ = true;
  out.role = track.role;
}

void SlamEstimator::make_untrusted(std::size_t j) {
  Track& track = *tracks_[j];
  track.role = LidarRole::initializing;
  track.hand_eye.reset();
  monitor_.restart(j);
  track.T_g_lidar = SE3(track.setup.T_base_lidar.rotation(), Vec3::Zero());
  track.own = std::make_unique<slam::Odometry>(config_.odometry, std::vector{with_extrinsic(track.setup, track.T_g_lidar)});
  track.recent.clear();
  track.report.covariance.reset();
  ++track.report.restarts;
  trusted_changed_ = true;
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

  trusted_changed_ = false;
  for (std::size_t j = 1; j < tracks_.size(); ++j) {
    if (!scans[j]) {
      tracks_[j]->recent.clear();
      tracks_[j]->pending.reset();
      continue;
    }
    start = Clock::now();
    if (tracks_[j]->role == LidarRole::initializing) {
      initialize(j, stamp, *scans[j], k, out.lidars[j]);
      out.seconds.initialization += seconds_since(start);
    } else if (tracks_[j]->role == LidarRole::calibrating && !last_odometry_.lost) {
      calibrate(j, stamp, *scans[j], k, out.lidars[j]);
      out.seconds.calibration += seconds_since(start);
    }
  }
  start = Clock::now();
  detect_shocks(k, out);
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

std::vector<Eigen::Vector3f> SlamEstimator::map_points() const {
  std::vector<Eigen::Vector3f> points = odometry_->plane_map().points();
  const std::vector<Eigen::Vector3f> edges = odometry_->edge_map().points();
  points.insert(points.end(), edges.begin(), edges.end());
  return points;
}

}  // namespace mlidar::pipelines
