#include "mlidar/slam/map_correspondences.hpp"

#include <cmath>
#include <limits>

#include "mlidar/slam/map_matcher.hpp"

namespace mlidar::slam {
namespace {

/// Search radius as in scan-to-map registration: at least the map's neighbourhood.
float search_radius_sq(const MapView& map, double max_residual_m) {
  const double radius = std::max(max_residual_m, map.config.neighborhood_radius_m);
  return static_cast<float>(radius * radius);
}

/// Distance of q from the line (eq 4.8's |r|).
double line_distance(const MapLine& line, const Vec3& q) {
  const Vec3 d = q - line.point;
  return (d - line.direction.dot(d) * line.direction).norm();
}

/// Calls on_plane(point, plane, |r|) / on_edge(point, line, |r|) for every kept correspondence.
template <typename OnPlane, typename OnEdge>
MapFit match_all(std::span<const Eigen::Vector3f> edges, std::span<const Eigen::Vector3f> planes, const SE3& T_world_points,
                 const MapView& map, double max_residual_m, OnPlane on_plane, OnEdge on_edge) {
  MapFit fit;
  const float radius_sq = search_radius_sq(map, max_residual_m);
  for (const auto& p : planes) {
    const Vec3 q = T_world_points * Vec3(p.cast<double>());
    const auto plane = match_plane(map.plane_map, q, radius_sq, map.config);
    if (!plane) continue;
    const double distance = std::abs(plane->normal.dot(q) + plane->offset);
    if (distance > max_residual_m) continue;
    on_plane(p, *plane);
    ++fit.planes;
    fit.residual_sum_m += distance;
  }
  for (const auto& p : edges) {
    const Vec3 q = T_world_points * Vec3(p.cast<double>());
    const auto line = match_line(map.edge_map, q, radius_sq, map.config);
    if (!line) continue;
    const double distance = line_distance(*line, q);
    if (distance > max_residual_m) continue;
    on_edge(p, *line);
    ++fit.edges;
    fit.residual_sum_m += distance;
  }
  return fit;
}

}  // namespace

double MapFit::mean_residual_m() const {
  const std::size_t matches = planes + edges;
  return matches == 0 ? std::numeric_limits<double>::quiet_NaN() : residual_sum_m / static_cast<double>(matches);
}

MapFit add_map_correspondences(const LidarFrameFeatures& features, int frame, int lidar, const SE3& T_world_lidar, const MapView& map,
                               double max_residual_m, WindowProblem& problem) {
  return match_all(
      features.edges, features.planes, T_world_lidar, map, max_residual_m,
      [&](const Eigen::Vector3f& p, const PlaneCoefficients& plane) {
        problem.planes.push_back({frame, lidar, p.cast<double>(), plane});
      },
      [&](const Eigen::Vector3f& p, const MapLine& line) {
        problem.edges.push_back({frame, lidar, p.cast<double>(), line.point, line.direction});
      });
}

}  // namespace mlidar::slam
