#pragma once
// A uniform 2D grid over the xy bounding boxes of bounded primitives, walked
// cell by cell along a ray (Amanatides & Woo, "A Fast Voxel Traversal
// Algorithm", Eurographics 1987). Outdoor scenes spread in xy, so a 2D grid
// with a z slab gives few candidates per cell and an early exit at the first
// cell whose exit lies beyond the nearest hit.
#include <cstdint>
#include <optional>
#include <vector>

#include "mlidar/sim/primitives.hpp"

namespace mlidar::sim {

/// Owns a copy of the primitives it indexes; immutable after construction,
/// so concurrent cast() calls are safe.
class UniformGrid {
 public:
  UniformGrid() = default;
  /// Every primitive must be bounded. cell_size in metres (> 0).
  UniformGrid(std::vector<Primitive> primitives, double cell_size);

  /// Nearest hit in (t_min, t_max], or none.
  std::optional<Hit> cast(const Ray& ray, double t_min, double t_max) const;

  const std::vector<Primitive>& primitives() const { return primitives_; }

 private:
  std::vector<Primitive> primitives_;
  Vec3 min_ = Vec3::Zero();
  Vec3 max_ = Vec3::Zero();
  double cell_size_ = 1.0;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<std::uint32_t> cell_start_;  ///< CSR offsets, nx*ny + 1 entries
  std::vector<std::uint32_t> cell_items_;  ///< primitive indices per cell

  int cell_index(int ix, int iy) const { return iy * nx_ + ix; }
  bool clip(const Ray& ray, double& t0, double& t1) const;
};

}  // namespace mlidar::sim
