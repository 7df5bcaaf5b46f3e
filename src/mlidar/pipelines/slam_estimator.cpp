#include "mlidar/pipelines/slam_estimator.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mlidar/slam/map_consistency.hpp"

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

}  // namespace

SlamEstimator::SlamEstimator(SlamConfig config, std::vector<slam::LidarSetup> lidars, ExtrinsicSource source,
                             const std::vector<std::optional<ExtrinsicDisagreement>>& disagreed)
    : config_(std::move(config)),
      source_(source),
      shock_(lidars.size(), config_.shock),
      extrinsic_check_(lidars.size(), config_.extrinsic_check.residual),
      history_(config_.start.appearance_after_frames + 1, static_cast<std::size_t>(std::max(config_.appearance.refine.frame_step, 1))) {
  if (lidars.empty()) throw std::invalid_argument("SlamEstimator: no LiDARs");
  tracks_.reserve(lidars.size());  // the tracks refer to config_, never moved after this
  for (std::size_t j = 0; j < lidars.size(); ++j) tracks_.emplace_back(std::move(lidars[j]), j == 0, source, config_);
  for (std::size_t j = 1; j < disagreed.size() && j < tracks_.size(); ++j)
    if (disagreed[j] && tracks_[j].extrinsic_given()) {
      ExtrinsicDisagreement known = *disagreed[j];
      known.from_first_frame = true;
      tracks_[j].given_disagrees(known, true);
    }
  odometry_ = std::make_unique<slam::Odometry>(config_.odometry, trusted_setups());
  if (config_.window.refine_odometry) pose_window_.emplace(config_);
}

std::vector<slam::LidarSetup> SlamEstimator::trusted_setups() {
  trusted_.clear();
  std::vector<slam::LidarSetup> setups;
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    if (tracks_[j].role() != LidarRole::trusted) continue;
    trusted_.push_back(j);
    setups.push_back(tracks_[j].setup());
  }
  return setups;
}

double SlamEstimator::base_residual(const std::vector<std::optional<Scan>>& scans) const {
  const std::vector<double>& registered = last_odometry_.lidar_mean_residual_m;
  if (!scans[0] || last_odometry_.flagged() || registered.empty() || !std::isfinite(registered[0])) return -1.0;
  return registered[0];  // the base is always trusted_[0]
}

void SlamEstimator::keep_for_appearance(std::size_t k, double stamp, const std::vector<std::optional<Scan>>& scans) {
  std::vector<bool> initializing(tracks_.size(), false);
  for (std::size_t j = 1; j < tracks_.size(); ++j) initializing[j] = tracks_[j].role() == LidarRole::initializing;
  if (config_.start.appearance_after_frames == 0 || std::find(initializing.begin(), initializing.end(), true) == initializing.end()) {
    history_.clear();  // nothing kept while every LiDAR is past its start
    return;
  }
  history_.add(k, stamp, last_odometry_.T_world_base, last_odometry_.flagged(), scans, initializing);
}

void SlamEstimator::step_tracks(const TrackFrame& frame, const std::vector<std::optional<Scan>>& scans, SlamFrame& out) {
  keep_for_appearance(frame.index, frame.stamp, scans);
  for (std::size_t j = 1; j < tracks_.size(); ++j) {
    const LidarRole before = tracks_[j].role();
    const auto start = Clock::now();
    TrackTransition transition = tracks_[j].step(frame, scans[j], out.lidars[j]);
    if (transition == TrackTransition::none && tracks_[j].appearance_due(frame.index))
      transition = tracks_[j].start_by_appearance(history_, tracks_[0].setup(), j, frame.index);
    if (scans[j] && before == LidarRole::initializing) out.seconds.initialization += seconds_since(start);
    if (scans[j] && before == LidarRole::calibrating && !frame.odometry->flagged()) out.seconds.calibration += seconds_since(start);
    if (transition == TrackTransition::converged) {
      shock_.reset(j);
      trusted_changed_ = true;
    }
  }
}

void SlamEstimator::detect_shocks(SlamFrame& out) {
  // The registration's own residuals at its last linearisation (its gate is the
  // adaptive correspondence threshold): no second search of the map.
  std::vector<double> residual(tracks_.size(), std::numeric_limits<double>::quiet_NaN());
  const std::vector<double>& registered = last_odometry_.lidar_mean_residual_m;
  for (std::size_t i = 0; i < trusted_.size() && i < registered.size(); ++i) {
    const std::size_t j = trusted_[i];
    if (out.lidars[j].scan_missing || last_odometry_.lost()) continue;  // a suspect frame's residuals count: a shock makes it one
    residual[j] = registered[i];
    out.lidars[j].mean_residual_m = std::isfinite(residual[j]) ? residual[j] : -1.0;
  }
  for (const std::size_t j : shock_.update(residual)) {
    out.lidars[j].shock = true;
    // The base defines the base frame: its trigger is reported, the others are not moved for it;
    // fixed extrinsics are given, so there a trigger is reported only.
    if (j == 0 || source_ != ExtrinsicSource::online || tracks_[j].role() != LidarRole::trusted) continue;
    tracks_[j].restart_after_shock();
    trusted_changed_ = true;
  }
}

void SlamEstimator::check_given_extrinsics(SlamFrame& out) {
  // The residuals detect_shocks recorded: the trusted odometry's at this frame.
  std::vector<double> residual(tracks_.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<bool> given(tracks_.size(), false);
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    if (out.lidars[j].mean_residual_m > 0.0) residual[j] = out.lidars[j].mean_residual_m;
    given[j] = j > 0 && tracks_[j].extrinsic_given();
  }
  std::vector<std::size_t> disagreeing = extrinsic_check_.update(residual, given);
  for (const std::size_t j : map_disagreements(given, out))
    if (!tracks_[j].disagreement() && std::find(disagreeing.begin(), disagreeing.end(), j) == disagreeing.end()) disagreeing.push_back(j);
  for (std::size_t j = 1; j < tracks_.size(); ++j)
    if (given[j]) out.lidars[j].residual_ratio = extrinsic_check_.median_ratio(j).value_or(-1.0);
  // Nothing registered yet with two or more LiDARs: the residuals say nothing, and any given one may be the cause.
  const bool lost_from_start = config_.extrinsic_check.enabled() && lost_from_start_ == kLostFromStartFrames && trusted_.size() > 1;
  if (lost_from_start) {
    disagreeing.clear();
    for (std::size_t j = 1; j < tracks_.size(); ++j)
      if (given[j] && !tracks_[j].disagreement()) disagreeing.push_back(j);
  }
  for (const std::size_t j : disagreeing) {
    out.lidars[j].extrinsic_disagrees = true;
    const bool by_map = out.lidars[j].map_ratio > config_.extrinsic_check.map_ratio;
    const ExtrinsicDisagreement disagreement{.frame = frames_ - 1,
                                             .residual_ratio = lost_from_start || by_map ? -1.0 : out.lidars[j].residual_ratio,
                                             .map_ratio = by_map ? out.lidars[j].map_ratio : -1.0,
                                             .frames_lost = lost_from_start,
                                             .after_shock = shock_.lidar(j).triggers > 0};
    tracks_[j].given_disagrees(disagreement, config_.extrinsic_check.recalibrate);
    if (!config_.extrinsic_check.recalibrate) continue;
    extrinsic_check_.reset(j);
    trusted_changed_ = true;
  }
}

std::vector<std::size_t> SlamEstimator::map_disagreements(const std::vector<bool>& given, SlamFrame& out) const {
  const std::size_t first = config_.extrinsic_check.map_first_frames;
  std::vector<std::size_t> found;
  const bool due = first > 0 && frames_ % first == 0 && std::has_single_bit(frames_ / first);  // first * 2^n frames
  if (!due || !config_.extrinsic_check.enabled() || trusted_set_changed_ || std::find(given.begin(), given.end(), true) == given.end())
    return found;
  // The map's sources are the trusted odometry's LiDAR indices: trusted_[i] is LiDAR i's track.
  const std::vector<slam::SourceConsistency> consistency = slam::map_consistency(odometry_->plane_map(), trusted_.size());
  for (std::size_t i = 0; i < consistency.size(); ++i) {
    const slam::SourceConsistency& c = consistency[i];
    const std::size_t j = trusted_.at(c.source);
    if (!given[j] || c.self_planes < kMapTestPlanes || c.cross_planes < kMapTestPlanes) continue;
    out.lidars[j].map_ratio = slam::consistency_ratio(consistency, i);
    if (out.lidars[j].map_ratio > config_.extrinsic_check.map_ratio) found.push_back(j);
  }
  return found;
}

SlamFrame SlamEstimator::process(double stamp, const std::vector<std::optional<Scan>>& scans) {
  if (scans.size() != tracks_.size()) throw std::invalid_argument("SlamEstimator::process: one scan (or nullopt) per LiDAR expected");
  const std::size_t k = frames_++;
  SlamFrame out;
  out.stamp = stamp;
  out.lidars.resize(tracks_.size());
  for (std::size_t j = 0; j < tracks_.size(); ++j) out.lidars[j].scan_missing = !scans[j].has_value();
  auto start = Clock::now();
  const bool calibrating = trusted_.size() < tracks_.size();  // some LiDAR is not registered by the odometry yet
  odometry_->set_selection_paused(calibrating && !odometry_->config().registration.selection.while_calibrating);
  last_odometry_ = odometry_->process(trusted_frame(stamp, scans, trusted_));
  out.lost = last_odometry_.lost();
  out.map_restarted = last_odometry_.map_restarted;
  if (k > 0 && !registered_once_) {
    registered_once_ = !out.lost;
    lost_from_start_ = out.lost ? lost_from_start_ + 1 : 0;
  }
  out.suspect = last_odometry_.suspect();
  out.T_world_base = last_odometry_.T_world_base;
  out.pose_covariance = pose_covariance_.add(last_odometry_, k == 0);
  out.selection = last_odometry_.selection_summary();
  if (out.selection)
    for (const slam::LidarSetup& lidar : odometry_->lidars()) out.selection_lidars.push_back(lidar.name);
  out.uncertain_features = last_odometry_.lidar_uncertain;
  out.mapping = last_odometry_.mapping;
  if (!out.uncertain_features.empty())
    for (const slam::LidarSetup& lidar : odometry_->lidars()) out.uncertainty_lidars.push_back(lidar.name);
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
  const TrackFrame frame{k, stamp, scans[0] ? &*scans[0] : nullptr, &last_odometry_, odometry_.get(), base_residual(scans)};
  step_tracks(frame, scans, out);
  start = Clock::now();
  detect_shocks(out);
  check_given_extrinsics(out);
  out.seconds.shock = seconds_since(start);
  if (trusted_changed_) {
    trusted_set_changed_ = true;
    odometry_->set_lidars(trusted_setups());  // from the next frame on; the map and world are kept
    out.trusted_changed = true;
  }
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    out.lidars[j].role = tracks_[j].role();
    out.calibrating = out.calibrating || out.lidars[j].role != LidarRole::trusted;
  }
  return out;
}

std::vector<SlamLidarReport> SlamEstimator::lidar_reports(std::span<const SlamFrame> frames) const {
  std::vector<SlamLidarReport> reports;
  for (std::size_t j = 0; j < tracks_.size(); ++j) reports.push_back(tracks_[j].report(frames, j));
  return reports;
}

std::vector<slam::WindowPose> SlamEstimator::unsettled_poses() const {
  return pose_window_ ? pose_window_->unsettled() : std::vector<slam::WindowPose>{};
}

}  // namespace mlidar::pipelines
