#pragma once
// Exact nearest-neighbour queries over 3D float points (nanoflann k-d tree,
// hidden behind this interface so callers do not see the library).
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace mlidar {

/// One neighbour: index into KdTree3f::points() and squared Euclidean distance.
struct Neighbor {
  std::uint32_t index = 0;
  float distance_sq = 0.0F;
};

/// A k-d tree that OWNS its points (pass a copy or std::move them in), so it
/// can never dangle. Immutable after construction: const queries may run
/// concurrently from several threads.
class KdTree3f {
 public:
  /// Builds the tree. Throws std::invalid_argument when a point is not finite
  /// or there are 2^32 points or more (callers drop NaNs first).
  explicit KdTree3f(std::vector<Eigen::Vector3f> points, std::size_t leaf_size = 10);
  ~KdTree3f();
  KdTree3f(KdTree3f&&) noexcept;
  KdTree3f& operator=(KdTree3f&&) noexcept;
  KdTree3f(const KdTree3f&) = delete;
  KdTree3f& operator=(const KdTree3f&) = delete;

  const std::vector<Eigen::Vector3f>& points() const;
  std::size_t size() const { return points().size(); }

  /// The min(k, size()) nearest points, closest first.
  std::vector<Neighbor> knn(const Eigen::Vector3f& query, std::size_t k) const;

  /// All points with squared distance <= radius^2, closest first.
  std::vector<Neighbor> radius_search(const Eigen::Vector3f& query, float radius) const;
  /// Same set, in no particular order, written into `out` (cleared first) so
  /// hot loops can reuse one buffer.
  void radius_search_unsorted(const Eigen::Vector3f& query, float radius, std::vector<Neighbor>& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mlidar
