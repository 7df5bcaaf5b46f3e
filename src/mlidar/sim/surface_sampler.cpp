#include "mlidar/sim/surface_sampler.hpp"

#include <cmath>
#include <stdexcept>

namespace mlidar::sim {
namespace {

/// A cube's index packed into 64 bits (21 bits per axis: +-1e6 cubes, 10 km at 1 cm).
std::uint64_t cube_key(const Vec3& point, double spacing) {
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto index = static_cast<std::int64_t>(std::floor(point[axis] / spacing)) + (std::int64_t{1} << 20);
    key = (key << 21) | (static_cast<std::uint64_t>(index) & ((std::uint64_t{1} << 21) - 1));
  }
  return key;
}

}  // namespace

SurfaceSampler::SurfaceSampler(double spacing, const SE3& T_frame_world)
    : spacing_(spacing), T_frame_world_(T_frame_world), R_frame_world_(T_frame_world.rotation_matrix()) {
  if (!(spacing > 0.0)) throw std::invalid_argument("SurfaceSampler: spacing must be positive");
}

void SurfaceSampler::add(const Vec3& point_world, const Vec3& normal_world) {
  const Vec3 point = T_frame_world_ * point_world;
  if (!occupied_.insert(cube_key(point, spacing_)).second) return;
  samples_.points.push_back(point.cast<float>());
  samples_.normals.push_back((R_frame_world_ * normal_world).normalized().cast<float>());
}

}  // namespace mlidar::sim
