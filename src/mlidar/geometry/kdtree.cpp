#include "mlidar/geometry/kdtree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <nanoflann.hpp>

namespace mlidar {
namespace {

/// nanoflann's dataset interface over the owned point vector.
struct PointsAdaptor {
  const std::vector<Eigen::Vector3f>* points = nullptr;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  float kdtree_get_pt(std::size_t index, std::size_t dim) const { return (*points)[index][static_cast<Eigen::Index>(dim)]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*unused*/) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointsAdaptor>, PointsAdaptor, 3, std::uint32_t>;

/// Result set that appends every point inside the radius straight into a Neighbor vector.
class RadiusCollector {
 public:
  // nanoflann keeps only distances strictly below worstDist(), so report the next float up
  // to include points exactly on the sphere (distance_sq == radius_sq).
  RadiusCollector(float radius_sq, std::vector<Neighbor>& out)
      : radius_sq_(radius_sq), bound_(std::nextafter(radius_sq, std::numeric_limits<float>::infinity())), out_(out) {}
  void init() { out_.clear(); }
  std::size_t size() const { return out_.size(); }
  bool full() const { return true; }
  bool addPoint(float distance_sq, std::uint32_t index) {
    if (distance_sq <= radius_sq_) out_.push_back({index, distance_sq});
    return true;
  }
  float worstDist() const { return bound_; }

 private:
  float radius_sq_;
  float bound_;
  std::vector<Neighbor>& out_;
};

void check_points(const std::vector<Eigen::Vector3f>& points) {
  if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("KdTree3f: too many points (" + std::to_string(points.size()) + ")");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) throw std::invalid_argument("KdTree3f: point " + std::to_string(i) + " is not finite");
  }
}

}  // namespace

struct KdTree3f::Impl {
  Impl(std::vector<Eigen::Vector3f> input, std::size_t leaf_size)
      : points(std::move(input)), adaptor{&points}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(leaf_size)) {}
  std::vector<Eigen::Vector3f> points;
  PointsAdaptor adaptor;
  Tree tree;
};

KdTree3f::KdTree3f(std::vector<Eigen::Vector3f> points, std::size_t leaf_size) {
  check_points(points);
  impl_ = std::make_unique<Impl>(std::move(points), std::max<std::size_t>(leaf_size, 1));
}

KdTree3f::~KdTree3f() = default;
KdTree3f::KdTree3f(KdTree3f&&) noexcept = default;
KdTree3f& KdTree3f::operator=(KdTree3f&&) noexcept = default;

const std::vector<Eigen::Vector3f>& KdTree3f::points() const { return impl_->points; }

std::vector<Neighbor> KdTree3f::knn(const Eigen::Vector3f& query, std::size_t k) const {
  k = std::min(k, size());
  std::vector<std::uint32_t> indices(k);
  std::vector<float> distances_sq(k);
  if (k == 0) return {};
  const std::size_t found = impl_->tree.knnSearch(query.data(), k, indices.data(), distances_sq.data());
  std::vector<Neighbor> neighbors(found);
  for (std::size_t i = 0; i < found; ++i) neighbors[i] = {indices[i], distances_sq[i]};
  return neighbors;
}

void KdTree3f::radius_search_unsorted(const Eigen::Vector3f& query, float radius, std::vector<Neighbor>& out) const {
  out.clear();
  if (size() == 0 || !(radius >= 0.0F)) return;
  RadiusCollector collector(radius * radius, out);
  impl_->tree.findNeighbors(collector, query.data(), nanoflann::SearchParams(32, 0.0F, false));
}

std::vector<Neighbor> KdTree3f::radius_search(const Eigen::Vector3f& query, float radius) const {
  std::vector<Neighbor> neighbors;
  radius_search_unsorted(query, radius, neighbors);
  std::sort(neighbors.begin(), neighbors.end(), [](const Neighbor& a, const Neighbor& b) {
    return a.distance_sq < b.distance_sq || (a.distance_sq == b.distance_sq && a.index < b.index);
  });
  return neighbors;
}

}  // namespace mlidar
