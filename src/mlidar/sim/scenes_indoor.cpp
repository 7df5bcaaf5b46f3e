// Indoor scenes: corner, room, corridor (see scenes.hpp).
#include <algorithm>

#include "mlidar/sim/scene.hpp"
#include "mlidar/sim/scene_layout.hpp"

namespace mlidar::sim::layout {
namespace {

/// Grows extent so each side is at least min_size long.
Extent2 at_least(Extent2 e, double min_size) {
  for (int a = 0; a < 2; ++a) {
    const double grow = std::max(0.0, min_size - (e.max[a] - e.min[a])) / 2.0;
    e.min[a] -= grow;
    e.max[a] += grow;
  }
  return e;
}

}  // namespace

Scene corner_scene(std::uint64_t seed, std::span<const Vec3> path) {
  std::mt19937_64 rng(seed);
  const Extent2 e = at_least(path_extent(path, uniform(rng, 3.0, 5.0)), 8.0);
  std::vector<Primitive> primitives{make_ground(0.0, Eigen::Vector2d::Zero(), 0.3)};
  const double height = uniform(rng, 4.0, 6.0);
  // Two perpendicular walls meeting at (max.x, max.y), each 2x the room side long.
  const Eigen::Vector2d corner = e.max;
  primitives.push_back(wall(corner - Eigen::Vector2d(0.0, 2.0 * (e.max.y() - e.min.y())), corner, 0.0, height, 0.6));
  primitives.push_back(wall(corner, corner - Eigen::Vector2d(2.0 * (e.max.x() - e.min.x()), 0.0), 0.0, height, 0.6));
  return Scene("corner", primitives, {});
}

Scene room_scene(std::uint64_t seed, std::span<const Vec3> path) {
  std::mt19937_64 rng(seed);
  const Extent2 e = at_least(path_extent(path, 3.0), 7.0);
  const double height = uniform(rng, 2.8, 3.4);
  std::vector<Primitive> primitives{make_ground(0.0, Eigen::Vector2d::Zero(), 0.3), slab(e, height, 0.7)};
  add_room_walls(e, height, 0.6, primitives);
  // Furniture against the walls and free-standing pillars, kept off the path.
  for (int tries = 0, placed = 0; tries < 200 && placed < 8; ++tries) {
    // Draws in statements of their own, last argument first (scene_layout.hpp: uniform).
    const double half_z = uniform(rng, 0.4, 1.0), half_y = uniform(rng, 0.3, 0.8), half_x = uniform(rng, 0.3, 1.0);
    const Vec3 half(half_x, half_y, half_z);
    const double y = uniform(rng, e.min.y() + half.y(), e.max.y() - half.y());
    const Eigen::Vector2d xy(uniform(rng, e.min.x() + half.x(), e.max.x() - half.x()), y);
    if (distance_to_path(path, xy) < half.head<2>().norm() + 1.0) continue;
    primitives.push_back(make_box(Vec3(xy.x(), xy.y(), half.z()), 0.0, half, uniform(rng, 0.2, 0.8)));
    ++placed;
  }
  for (int tries = 0, placed = 0; tries < 100 && placed < 2; ++tries) {
    const double y = uniform(rng, e.min.y() + 1.0, e.max.y() - 1.0);
    const Eigen::Vector2d xy(uniform(rng, e.min.x() + 1.0, e.max.x() - 1.0), y);
    if (distance_to_path(path, xy) < 1.5) continue;
    primitives.push_back(make_cylinder(Vec3(xy.x(), xy.y(), height / 2), 0.25, height / 2, 0.5));
    ++placed;
  }
  return Scene("room", primitives, {});
}

Scene corridor_scene(std::uint64_t seed, std::span<const Vec3> path) {
  std::mt19937_64 rng(seed);
  Extent2 e = path_extent(path, uniform(rng, 1.0, 1.5));
  // The corridor runs along the path's longer side; its ends lie 170 m beyond
  // the path, past every model's maximum range.
  const int along = (e.max.x() - e.min.x()) >= (e.max.y() - e.min.y()) ? 0 : 1;
  e.min[along] -= 170.0;
  e.max[along] += 170.0;
  const double height = uniform(rng, 2.6, 3.2);
  std::vector<Primitive> primitives{make_ground(0.0, Eigen::Vector2d::Zero(), 0.3), slab(e, height, 0.7)};
  add_room_walls(e, height, 0.6, primitives);
  return Scene("corridor", primitives, {}, 4.0);
}

}  // namespace mlidar::sim::layout
