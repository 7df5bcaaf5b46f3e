// LidarTrack's Calibrating state: the calibration window (eq 4.21) against
// the trusted map, Algorithm 1 (lines 5-11) and the residual-gated
// re-initialization.
#include <utility>

#include "mlidar/core/conversions.hpp"
#include "mlidar/pipelines/slam_lidar_track.hpp"

#include "mlidar/core/covariance.hpp"

namespace mlidar::pipelines {
namespace {

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

void record_window(const slam::CalibrationWindowResult& window, const calib::WindowVerdict& verdict, SlamLidarFrame& out) {
  out.mean_residual_m = window.fit.mean_residual_m();
  out.lambda_min = verdict.lambda_min;
  out.window_estimate = window.T_base_lidar;
  out.window_information = window.information;
  out.window_residual_variance_m2 = window.residual_variance_m2;
  out.window_step_m = window.last_step_m;
  out.window_step_deg = rad_to_deg(window.last_step_rad);
  out.window_settled = window.settled;
  out.accepted = verdict.accepted;
}

}  // namespace

TrackTransition LidarTrack::calibrate(Calibrating& state, const TrackFrame& frame, const Scan& scan, SlamLidarFrame& out) {
  // The scan is deskewed once the next frame's pose is known, with the
  // velocity over its own sweep (the previous frame's velocity, a frame late,
  // biased the extrinsic by centimetres under handheld motion).
  const SE3& T_world_base = frame.odometry->T_world_base;
  std::optional<Pending> previous = std::exchange(state.pending, Pending{scan, frame.stamp, T_world_base});
  if (!previous || !(frame.stamp > previous->stamp)) return TrackTransition::none;
  const slam::BodyVelocity velocity =
      slam::BodyVelocity::from_relative_pose(previous->T_world_base.inverse() * T_world_base, frame.stamp - previous->stamp);
  slam::StageSeconds unused{};
  slam::run_front_end(previous->scan, previous->stamp, setup_, velocity, config_->odometry.front_end, state.workspace, state.features,
                      unused);
  state.window.push_back({to_lidar_frame(state.features, setup_.T_base_lidar), previous->T_world_base});
  if (state.window.size() > static_cast<std::size_t>(config_->window.size + 1)) state.window.erase(state.window.begin());

  // Eq 4.21: the window's poses are fixed by the map; T_base_lidar_j is the variable.
  // The trusted odometry's plane fit: its map, fitted as its LiDARs' noise allows (plane_min_extent_m).
  const slam::MapView map{frame.trusted->edge_map(), frame.trusted->plane_map(), frame.trusted->config().registration};
  slam::CalibrationWindowOptions options;
  options.huber_delta_m = config_->odometry.registration.huber_delta_m;
  options.settle_passes = config_->window.calibration_settle_passes;
  const slam::CalibrationWindowResult window = slam::solve_calibration_window(state.window, setup_.T_base_lidar, map, options);
  if (!window.solved) return TrackTransition::none;
  const calib::WindowVerdict verdict =
      monitor_.add_window(0, window.T_base_lidar, window.information, window.residual_variance_m2, window.settled);
  record_window(window, verdict, out);
  // A constrained window that had not settled still moves the next window's start (it would otherwise restart from here).
  if (verdict.constrained) setup_.T_base_lidar = window.T_base_lidar;
  if (verdict.accepted) state.high_residual_windows = 0;
  if (verdict.converged_now) {
    // Algorithm 1 lines 8-11: the mean of L_calib accepted estimates, covariance alpha Xi_calib.
    const calib::LidarCalibrationState& converged = monitor_.lidar(0);
    setup_.T_base_lidar = converged.T_base_lidar;
    const Mat6 scaled = config_->window.extrinsic_covariance_scale * converged.covariance;
    setup_.extrinsic_covariance = covariance_in_left_tangent(converged.T_base_lidar, scaled);  // eq 4.24 for the mapping
    state_ = Trusted{scaled, converged.covariance_parts};
    return TrackTransition::converged;
  }
  if (!stays_far_from_the_map(state, frame, out)) return TrackTransition::none;
  monitor_.restart(0);
  state_ = start_initializing(true);
  out.reinitialized = true;
  return TrackTransition::reinitialized;
}

bool LidarTrack::stays_far_from_the_map(Calibrating& state, const TrackFrame& frame, const SlamLidarFrame& out) const {
  // A hand-eye start the window cannot pull in (campus seed 7: 1.5 m off) leaves
  // the window's residual against the map far above the base's own at the
  // same frame (median ratio 3.7 there, 0.7-1.1 on healthy runs); after
  // `windows` such windows without an acceptance, the LiDAR starts again.
  const StartParams& params = config_->start;
  if (params.reinitialize_windows == 0 || out.accepted || out.mean_residual_m < 0.0 || !(frame.base_residual_m > 0.0)) return false;
  if (out.mean_residual_m > params.reinitialize_residual_ratio * frame.base_residual_m) ++state.high_residual_windows;
  return state.high_residual_windows >= params.reinitialize_windows;
}

}  // namespace mlidar::pipelines
