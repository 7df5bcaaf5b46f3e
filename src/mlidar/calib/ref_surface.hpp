#pragma once
// The reference side of pairwise registration: a k-d tree over the reference
// cloud with surface normals estimated on demand (PCA of the k nearest
// neighbours, thesis eq 2.2), plus the voxel filter and the overlap factor
// (thesis eq 3.13-3.14) that the pairwise refinement reports.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"
#include "mlidar/geometry/kdtree.hpp"

namespace mlidar::calib {

/// One point per occupied voxel of side `voxel_size` (the centroid of the
/// points in it), in the order the voxels are first seen: deterministic.
/// Non-finite points are dropped. Throws std::invalid_argument for voxel_size <= 0.
std::vector<Eigen::Vector3f> voxel_downsample(std::span<const Eigen::Vector3f> points, double voxel_size);

struct SurfaceConfig {
  std::size_t normal_neighbours = 20;   ///< k of the PCA
  double max_neighbour_distance = 1.5;  ///< m; a farther k-th neighbour makes the normal invalid
  double max_planarity = 0.1;           ///< lambda_min / lambda_mid above this: not a plane
  double min_line_ratio = 0.05;         ///< lambda_mid / lambda_max below this: points on a line (one ring)
};

/// A reference cloud ready for point-to-plane queries. Owns its tree; the
/// normal cache makes normal_at non-const, so one RefSurface serves one thread.
class RefSurface {
 public:
  RefSurface(std::vector<Eigen::Vector3f> points, const SurfaceConfig& config = {});

  const KdTree3f& tree() const { return tree_; }
  /// Unit normal of the surface at point `index`, or nullopt where the
  /// neighbourhood is not planar (a corner, a tree, a single ring).
  std::optional<Vec3> normal_at(std::uint32_t index);

 private:
  KdTree3f tree_;
  SurfaceConfig config_;
  std::vector<std::uint8_t> state_;  ///< 0 not computed, 1 valid, 2 invalid
  std::vector<Eigen::Vector3f> normals_;
};

/// Overlap of two clouds under T_a_b (thesis eq 3.13-3.14): S^b are the
/// points of b with a point of a within `radius` after mapping b into a, S^a
/// the points of a with a mapped point of b within `radius`.
struct Overlap {
  double fraction_b = 0.0;                                  ///< |S^b| / |P^b|
  double fraction_a = 0.0;                                  ///< |S^a| / |P^a|
  double omega() const { return fraction_a * fraction_b; }  ///< eq 3.14
};
/// tree_a indexes P^a; points_b is P^b in its own frame.
Overlap overlap(const KdTree3f& tree_a, std::span<const Eigen::Vector3f> points_b, const SE3& T_a_b, double radius);

}  // namespace mlidar::calib
