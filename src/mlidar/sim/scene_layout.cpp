#include "mlidar/sim/scene_layout.hpp"

#include <algorithm>
#include <limits>

namespace mlidar::sim::layout {

Extent2 path_extent(std::span<const Vec3> path, double margin) {
  Extent2 extent{Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()),
                 Eigen::Vector2d::Constant(-std::numeric_limits<double>::infinity())};
  for (const auto& p : path) {
    extent.min = extent.min.cwiseMin(p.head<2>());
    extent.max = extent.max.cwiseMax(p.head<2>());
  }
  extent.min.array() -= margin;
  extent.max.array() += margin;
  return extent;
}

double distance_to_path(std::span<const Vec3> path, const Eigen::Vector2d& xy) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : path) best = std::min(best, (p.head<2>() - xy).squaredNorm());
  return std::sqrt(best);
}

Primitive wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1, double reflectivity) {
  const Eigen::Vector2d along = (b - a).normalized();
  Mat3 axes;
  axes.col(0) = Vec3(along.x(), along.y(), 0.0);
  axes.col(1) = Vec3::UnitZ();
  axes.col(2) = axes.col(0).cross(axes.col(1));
  const Eigen::Vector2d mid = 0.5 * (a + b);
  return make_rectangle(Vec3(mid.x(), mid.y(), 0.5 * (z0 + z1)), axes, 0.5 * (b - a).norm(), 0.5 * (z1 - z0), reflectivity);
}

Primitive slab(const Extent2& extent, double z, double reflectivity) {
  const Eigen::Vector2d mid = 0.5 * (extent.min + extent.max);
  const Eigen::Vector2d half = 0.5 * (extent.max - extent.min);
  return make_rectangle(Vec3(mid.x(), mid.y(), z), Mat3::Identity(), half.x(), half.y(), reflectivity);
}

void add_room_walls(const Extent2& e, double height, double reflectivity, std::vector<Primitive>& out) {
  const Eigen::Vector2d c00 = e.min;
  const Eigen::Vector2d c10(e.max.x(), e.min.y());
  const Eigen::Vector2d c11 = e.max;
  const Eigen::Vector2d c01(e.min.x(), e.max.y());
  out.push_back(wall(c00, c10, 0.0, height, reflectivity));
  out.push_back(wall(c10, c11, 0.0, height, reflectivity));
  out.push_back(wall(c11, c01, 0.0, height, reflectivity));
  out.push_back(wall(c01, c00, 0.0, height, reflectivity));
}

double uniform(std::mt19937_64& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

}  // namespace mlidar::sim::layout
