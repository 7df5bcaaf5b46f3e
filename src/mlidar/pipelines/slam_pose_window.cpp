#include "mlidar/pipelines/slam_pose_window.hpp"

namespace mlidar::pipelines {
namespace {

/// Every trusted LiDAR's features (base frame, the frame's time centroid) as one set: eq 4.22 with fixed extrinsics.
slam::LidarFrameFeatures trusted_features(const std::vector<slam::LidarFeatures>& per_lidar) {
  slam::LidarFrameFeatures all;
  for (const slam::LidarFeatures& f : per_lidar) {
    all.edges.insert(all.edges.end(), f.edges.begin(), f.edges.end());
    all.planes.insert(all.planes.end(), f.planes.begin(), f.planes.end());
  }
  return all;
}

}  // namespace

slam::OdometryWindowConfig odometry_window_config(const SlamConfig& config) {
  slam::OdometryWindowConfig out;
  const slam::OdometryConfig& odometry = config.odometry;
  out.size = config.window.size;
  out.pivot = config.window.pivot;
  out.plane_voxel_m = odometry.plane_voxel_m;
  out.edge_voxel_m = odometry.edge_voxel_m;
  out.plane_points_per_voxel = odometry.plane_points_per_voxel;
  out.edge_points_per_voxel = odometry.edge_points_per_voxel;
  out.local_map_radius_m = odometry.local_map_radius_m;
  out.registration = odometry.registration;
  out.solver.huber_delta_m = odometry.registration.huber_delta_m;
  return out;
}

std::optional<slam::OdometryWindowUpdate> SlamPoseWindow::add(std::size_t frame, const slam::FrameResult& result,
                                                              const slam::Odometry& odometry) {
  if (frame < 1 || result.flagged()) return std::nullopt;
  if (!window_) {
    config_.registration = odometry.config().registration;  // its map fitted as the odometry fits it (its LiDARs' noise)
    window_.emplace(config_, odometry.edge_map(), odometry.plane_map());  // frames 0 and 1, as rebuilt at frame 1
    return std::nullopt;
  }
  // registration.T_world_base: the pose at the time centroid, where the features are.
  const SE3& T_world_centroid = result.registration.T_world_base;
  return window_->add(frame, trusted_features(odometry.lidar_features()), T_world_centroid,
                      T_world_centroid.inverse() * result.T_world_base);
}

std::vector<slam::WindowPose> SlamPoseWindow::unsettled() const { return window_ ? window_->unsettled() : std::vector<slam::WindowPose>{}; }

}  // namespace mlidar::pipelines
