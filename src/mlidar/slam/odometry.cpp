#include "mlidar/slam/odometry.hpp"

#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <tbb/parallel_for.h>

namespace mlidar::slam {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void append_transformed(const SE3& T, std::span<const Eigen::Vector3f> points, std::vector<Eigen::Vector3f>& out) {
  const std::size_t begin = out.size();
  out.resize(begin + points.size());
  transform_points(T, points, std::span(out).subspan(begin));
}

}  // namespace

Odometry::Odometry(OdometryConfig config, std::vector<LidarSetup> lidars)
    : config_(std::move(config)), lidars_(std::move(lidars)), workspaces_(lidars_.size()), features_(lidars_.size()),
      edge_map_(config_.edge_voxel_m, config_.edge_points_per_voxel), plane_map_(config_.plane_voxel_m, config_.plane_points_per_voxel) {
  if (lidars_.empty()) throw std::invalid_argument("Odometry: no LiDARs");
}

BodyVelocity Odometry::predicted_velocity(double dt) const {
  if (poses_.size() < 2 || !(dt > 0.0)) return {};
  const auto& a = poses_[poses_.size() - 2];
  const auto& b = poses_.back();
  return BodyVelocity::from_relative_pose(a.T_world_base.inverse() * b.T_world_base, b.stamp - a.stamp);
}

void Odometry::adapt_threshold(const SE3& prediction, const SE3& estimate) {
  const SE3 error = prediction.inverse() * estimate;
  const double angle = so3_log(error.rotation()).norm();
  const double metres = error.translation().norm() + 2.0 * config_.reference_range_m * std::sin(angle / 2.0);
  error_sq_sum_ += metres * metres;
  ++error_count_;
}

RegistrationResult Odometry::register_robustly(const SE3& prediction, FrameResult& frame) {
  const double threshold = error_count_ == 0 ? config_.initial_threshold_m
                                             : std::max(config_.min_threshold_m, 3.0 * std::sqrt(error_sq_sum_ / static_cast<double>(error_count_)));
  frame.threshold_m = threshold;
  RegistrationResult best = register_scan_to_map(edges_, planes_, edge_map_, plane_map_, prediction, threshold, config_.registration);
  if (best.match_ratio() >= config_.min_match_ratio) return best;
  frame.retried = true;
  for (const double yaw_deg : config_.retry_yaw_deg) {
    const SE3 turn(so3_exp(Vec3(0, 0, yaw_deg * std::numbers::pi / 180.0)), Vec3::Zero());
    // A coarse pass with the initial (wide) threshold, then a fine pass.
    const RegistrationResult coarse = register_scan_to_map(edges_, planes_, edge_map_, plane_map_, prediction * turn,
                                                           std::max(threshold, config_.initial_threshold_m), config_.registration);
    RegistrationResult fine = register_scan_to_map(edges_, planes_, edge_map_, plane_map_, coarse.T_world_base, threshold, config_.registration);
    if (fine.match_ratio() > best.match_ratio()) best = fine;
    if (best.match_ratio() >= config_.min_match_ratio) break;
  }
  return best;
}

FrameResult Odometry::process(const Frame& frame) {
  if (frame.scans.size() != lidars_.size()) throw std::invalid_argument("Odometry::process: frame has a different number of scans than LiDARs");
  FrameResult result;
  result.stamp = frame.stamp;
  const double dt = poses_.empty() ? 0.0 : frame.stamp - poses_.back().stamp;
  const BodyVelocity velocity = predicted_velocity(dt);
  const SE3 prediction = poses_.empty() ? SE3::identity() : poses_.back().T_world_base * velocity.pose_at(dt);

  std::vector<StageSeconds> per_lidar(lidars_.size(), StageSeconds{});
  tbb::parallel_for(std::size_t{0}, lidars_.size(), [&](std::size_t i) {
    run_front_end(frame.scans[i], frame.stamp, lidars_[i], velocity, config_.front_end, workspaces_[i], features_[i], per_lidar[i]);
  });
  edges_.clear();
  planes_.clear();
  for (std::size_t i = 0; i < lidars_.size(); ++i) {
    for (std::size_t s = 0; s < kStageCount; ++s) result.seconds[s] += per_lidar[i][s];
    result.points_in += frame.scans[i].size();
    edges_.insert(edges_.end(), features_[i].edges.begin(), features_[i].edges.end());
    planes_.insert(planes_.end(), features_[i].planes.begin(), features_[i].planes.end());
  }
  result.edge_features = edges_.size();
  result.plane_features = planes_.size();

  auto start = std::chrono::steady_clock::now();
  if (poses_.empty()) {
    result.T_world_base = SE3::identity();
    result.registration.converged = true;
  } else {
    result.registration = register_robustly(prediction, result);
    result.T_world_base = result.registration.T_world_base;
    result.lost = result.registration.match_ratio() < config_.lost_match_ratio;
    if (result.lost) result.T_world_base = prediction;  // flagged, not silently trusted
    else if ((prediction.inverse() * poses_.back().T_world_base).translation().norm() >= config_.min_motion_m)
      adapt_threshold(prediction, result.T_world_base);
  }
  result.seconds[static_cast<std::size_t>(Stage::kRegistration)] += seconds_since(start);

  start = std::chrono::steady_clock::now();
  if (!result.lost) {
    std::vector<Eigen::Vector3f> world;
    append_transformed(result.T_world_base, edges_, world);
    edge_map_.add(world);
    world.clear();
    append_transformed(result.T_world_base, planes_, world);
    plane_map_.add(world);
    const Eigen::Vector3f origin = result.T_world_base.translation().cast<float>();
    edge_map_.remove_far(origin, config_.local_map_radius_m);
    plane_map_.remove_far(origin, config_.local_map_radius_m);
  }
  result.seconds[static_cast<std::size_t>(Stage::kMapUpdate)] += seconds_since(start);
  poses_.push_back({frame.stamp, result.T_world_base});
  return result;
}

}  // namespace mlidar::slam
