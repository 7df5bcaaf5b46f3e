#pragma once
// Window correspondences of one LiDAR's features against the local maps
// (thesis eq 4.21: an auxiliary LiDAR's features at a frame whose pose the
// map fixes). A feature x (LiDAR frame) goes to the world point
// q = T_world_base * T_base_lidar * x, where the map's plane (eq 4.7) or line
// (eq 4.8) around q is fitted (map_matcher.hpp); a correspondence is kept
// when q lies within max_residual_m of it.
#include <span>

#include <Eigen/Core>

#include "mlidar/slam/scan_to_map.hpp"
#include "mlidar/slam/voxel_map.hpp"
#include "mlidar/slam/window_problem.hpp"

namespace mlidar::slam {

/// Features of one LiDAR in its own frame (metres).
struct LidarFrameFeatures {
  std::vector<Eigen::Vector3f> edges;
  std::vector<Eigen::Vector3f> planes;
};

/// The local maps and how to search them.
struct MapView {
  const VoxelMap& edge_map;
  const VoxelMap& plane_map;
  const RegistrationConfig& config;
};

/// How well a set of features fits the map: the mean point-to-plane /
/// point-to-line distance over the kept correspondences.
struct MapFit {
  std::size_t planes = 0;
  std::size_t edges = 0;
  double residual_sum_m = 0.0;
  double mean_residual_m() const;  ///< NaN when nothing matched
};

/// Appends the correspondences of `features` at window frame `frame` for
/// LiDAR `lidar` to `problem` (planes and edges) and returns their fit.
MapFit add_map_correspondences(const LidarFrameFeatures& features, int frame, int lidar, const SE3& T_world_lidar, const MapView& map,
                               double max_residual_m, WindowProblem& problem);

}  // namespace mlidar::slam
