#pragma once
// Internal helpers shared by the scene generators: the path's extent and
// clearance checks, and wall/room builders.
#include <random>
#include <span>
#include <vector>

#include "mlidar/sim/primitives.hpp"

namespace mlidar::sim::layout {

struct Extent2 {
  Eigen::Vector2d min;
  Eigen::Vector2d max;
};

/// xy bounding box of the path, grown by margin.
Extent2 path_extent(std::span<const Vec3> path, double margin);
/// Smallest horizontal distance from (x, y) to the path samples.
double distance_to_path(std::span<const Vec3> path, const Eigen::Vector2d& xy);

/// A vertical wall from a to b (xy), from z0 to z1.
Primitive wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1, double reflectivity);
/// A horizontal rectangle at height z covering extent.
Primitive slab(const Extent2& extent, double z, double reflectivity);
/// Four walls around extent from the floor to height.
void add_room_walls(const Extent2& extent, double height, double reflectivity, std::vector<Primitive>& out);

/// Where several draws build one value, each is a statement of its own: the
/// order of function arguments is unspecified (gcc took them last first, clang
/// first first), and a dataset must not depend on the compiler. They are taken
/// last argument first, as gcc did, so datasets made before stay identical.
double uniform(std::mt19937_64& rng, double lo, double hi);

}  // namespace mlidar::sim::layout

namespace mlidar::sim {
class Scene;
}

namespace mlidar::sim::layout {
// Generators (scenes_indoor.cpp, scenes_outdoor.cpp), dispatched by make_scene.
Scene corner_scene(std::uint64_t seed, std::span<const Vec3> path);
Scene room_scene(std::uint64_t seed, std::span<const Vec3> path);
Scene corridor_scene(std::uint64_t seed, std::span<const Vec3> path);
Scene campus_scene(std::uint64_t seed, std::span<const Vec3> path);
Scene street_scene(std::uint64_t seed, std::span<const Vec3> path);
}  // namespace mlidar::sim::layout
