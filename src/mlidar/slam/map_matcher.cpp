#include "mlidar/slam/map_matcher.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace mlidar::slam {
namespace {

using Neighbours = std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors>;

}  // namespace

bool fit_neighbourhood(const Neighbours& points, int count, Neighbourhood& out) {
  Vec3 mean = Vec3::Zero();
  for (int i = 0; i < count; ++i) mean += points[static_cast<std::size_t>(i)].cast<double>();
  mean /= count;
  Mat3 covariance = Mat3::Zero();
  for (int i = 0; i < count; ++i) {
    const Vec3 d = points[static_cast<std::size_t>(i)].cast<double>() - mean;
    covariance.noalias() += d * d.transpose();
  }
  out.mean = mean;
  out.eigen.computeDirect(covariance / count);
  return out.eigen.info() == Eigen::Success;
}

std::optional<PlaneCoefficients> match_plane(const VoxelMap& plane_map, const Vec3& q_world, float search_radius_sq,
                                             const RegistrationConfig& config) {
  Neighbours near;
  const Eigen::Vector3f q = q_world.cast<float>();
  int count = plane_map.nearest(q, std::max(config.neighbors, config.plane_neighbors_max), search_radius_sq, near);
  // Nearest first: past `neighbors`, keep only the neighbours within the extra radius.
  const auto extra_sq = static_cast<float>(config.plane_extra_radius_m * config.plane_extra_radius_m);
  while (count > config.neighbors && (near[static_cast<std::size_t>(count - 1)] - q).squaredNorm() > extra_sq) --count;
  Neighbourhood hood;
  if (count < 3 || !fit_neighbourhood(near, count, hood)) return std::nullopt;
  // Colinear neighbours (one scan line) leave the normal's direction free about the line.
  if (hood.eigen.eigenvalues()(1) < config.plane_spread * hood.eigen.eigenvalues()(0)) return std::nullopt;
  // Narrower than the range noise: the noise along the beams, not the surface, sets the normal.
  if (hood.eigen.eigenvalues()(1) < config.plane_min_extent_m * config.plane_min_extent_m) return std::nullopt;
  const PlaneCoefficients plane{hood.eigen.eigenvectors().col(0), -hood.eigen.eigenvectors().col(0).dot(hood.mean)};
  for (int i = 0; i < count; ++i)
    if (std::abs(plane.normal.dot(near[static_cast<std::size_t>(i)].cast<double>()) + plane.offset) > config.plane_tolerance_m)
      return std::nullopt;
  return plane;
}

std::optional<MapLine> match_line(const VoxelMap& edge_map, const Vec3& q_world, float search_radius_sq, const RegistrationConfig& config) {
  Neighbours near;
  const int count = edge_map.nearest(q_world.cast<float>(), config.neighbors, search_radius_sq, near);
  Neighbourhood hood;
  if (count < 3 || !fit_neighbourhood(near, count, hood)) return std::nullopt;
  const Vec3 values = hood.eigen.eigenvalues();
  if (values(2) < config.edge_linearity * values(1)) return std::nullopt;
  const Vec3 direction = hood.eigen.eigenvectors().col(2);
  for (int i = 0; i < count; ++i) {
    const Vec3 d = near[static_cast<std::size_t>(i)].cast<double>() - hood.mean;
    if ((d - direction.dot(d) * direction).norm() > config.edge_tolerance_m) return std::nullopt;
  }
  return MapLine{hood.mean, direction};
}

}  // namespace mlidar::slam
