#include "mlidar/slam/voxel_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mlidar::slam {

VoxelMap::VoxelMap(double voxel_size, int max_points_per_voxel) : voxel_size_(voxel_size), max_points_(max_points_per_voxel) {
  if (!(voxel_size > 0.0) || max_points_per_voxel < 1)
    throw std::invalid_argument("VoxelMap: voxel_size must be > 0 and max_points_per_voxel >= 1");
}

void VoxelMap::insert(const Eigen::Vector3f& p, const PointCovariance* covariance, std::uint8_t source) {
  if (!p.allFinite()) return;
  const VoxelKey key = key_of(p);
  auto [it, added] = map_.try_emplace(key);
  Bucket& bucket = it.value();
  if (added) {
    if (free_slots_.empty()) {
      if (pool_.size() + static_cast<std::size_t>(max_points_) > std::numeric_limits<std::uint32_t>::max())
        throw std::length_error("VoxelMap: more than 2^32 point slots (too many voxels or points per voxel)");
      bucket.first = static_cast<std::uint32_t>(pool_.size());
      pool_.resize(pool_.size() + static_cast<std::size_t>(max_points_));
    } else {
      bucket.first = free_slots_.back();
      free_slots_.pop_back();
    }
  }
  if (static_cast<int>(bucket.count) >= max_points_) return;
  if (covariance != nullptr) {
    auto& kept = covariances_[key];
    kept.resize(bucket.count);  // points added without a covariance before this one: zero
    kept.push_back(*covariance);
  }
  if (source != kNoSource) {
    auto& kept = sources_[key];
    kept.resize(bucket.count, kNoSource);
    kept.push_back(source);
  }
  pool_[bucket.first + bucket.count++] = p;
}

void VoxelMap::add(std::span<const Eigen::Vector3f> points) {
  for (const auto& p : points) insert(p, nullptr);
}

void VoxelMap::add(std::span<const Eigen::Vector3f> points, std::span<const PointCovariance> covariances) {
  if (points.size() != covariances.size()) throw std::invalid_argument("VoxelMap::add: one covariance per point");
  for (std::size_t i = 0; i < points.size(); ++i) insert(points[i], &covariances[i]);
}

void VoxelMap::add(std::span<const CovariantPoint> points) {
  for (const CovariantPoint& p : points) insert(p.point, &p.covariance, p.source);
}

void VoxelMap::add(std::span<const Eigen::Vector3f> points, std::span<const std::uint8_t> sources) {
  if (points.size() != sources.size()) throw std::invalid_argument("VoxelMap::add: one source per point");
  for (std::size_t i = 0; i < points.size(); ++i) insert(points[i], nullptr, sources[i]);
}

void VoxelMap::remove_far(const Eigen::Vector3f& origin, double max_distance) {
  const float limit_sq = static_cast<float>(max_distance * max_distance);
  for (auto it = map_.begin(); it != map_.end();) {
    if ((pool_[it->second.first] - origin).squaredNorm() > limit_sq) {
      free_slots_.push_back(it->second.first);
      covariances_.erase(it->first);
      sources_.erase(it->first);
      it = map_.erase(it);
    } else {
      ++it;
    }
  }
}

namespace {

/// A neighbour of the query's voxel as, per axis, 0 (the same layer), 1 (the layer on the side of the voxel the
/// query is nearer to, at most half an edge away) or 2 (the far side, at least half an edge away).
using Sides = std::array<std::uint8_t, 3>;

/// The 26 neighbours, those with fewer far sides, then fewer near sides, first: so the boxes nearest a query
/// usually come first and tighten the k-th best distance before the farther ones are judged.
constexpr std::array<Sides, 26> kNeighbourSides = [] {
  std::array<Sides, 26> order{};
  std::size_t next = 0;
  for (int far = 0; far <= 3; ++far)
    for (int near = 0; near + far <= 3; ++near)
      for (std::uint8_t x = 0; x <= 2; ++x)
        for (std::uint8_t y = 0; y <= 2; ++y)
          for (std::uint8_t z = 0; z <= 2; ++z)
            if ((x == 1) + (y == 1) + (z == 1) == near && (x == 2) + (y == 2) + (z == 2) == far && near + far > 0)
              order[next++] = {x, y, z};
  return order;
}();

/// The neighbours before this index in kNeighbourSides have no far side.
constexpr std::size_t kFirstWithFarSide = [] {
  std::size_t i = 0;
  while (i < kNeighbourSides.size() && kNeighbourSides[i][0] != 2 && kNeighbourSides[i][1] != 2 && kNeighbourSides[i][2] != 2) ++i;
  return i;
}();
static_assert(kFirstWithFarSide == 7);

/// One axis of a query's position in its voxel: per side (same, near, far) the voxel offset and the squared gap
/// to that layer's box.
struct AxisLayers {
  std::array<std::int32_t, 3> offset;
  std::array<float, 3> gap_sq;
};

/// `fraction` in [0, 1): where the query lies along the axis of its voxel of edge `size`.
AxisLayers axis_layers(float fraction, float size) {
  const float below = fraction * size;
  const float above = (1.0F - fraction) * size;
  if (fraction < 0.5F) return {{0, -1, 1}, {0.0F, below * below, above * above}};
  return {{0, 1, -1}, {0.0F, above * above, below * below}};
}

}  // namespace

int VoxelMap::nearest(const Eigen::Vector3f& q, int k, float max_distance_sq, std::array<Eigen::Vector3f, kMaxNeighbors>& out) const {
  return search<false>(q, k, max_distance_sq, out, [](const std::vector<std::uint8_t>*, std::size_t) { return true; });
}

int VoxelMap::nearest_by_source(const Eigen::Vector3f& q, int k, float max_distance_sq, std::uint8_t source, bool same_source,
                                std::array<Eigen::Vector3f, kMaxNeighbors>& out) const {
  return search<true>(q, k, max_distance_sq, out, [&](const std::vector<std::uint8_t>* voxel_sources, std::size_t i) {
    const std::uint8_t of_point = voxel_sources != nullptr && i < voxel_sources->size() ? (*voxel_sources)[i] : kNoSource;
    return (of_point == source) == same_source;
  });
}

template <bool kBySource, typename Keep>
int VoxelMap::search(const Eigen::Vector3f& q, int k, float max_distance_sq, std::array<Eigen::Vector3f, kMaxNeighbors>& out,
                     const Keep& keep) const {
  k = std::min(k, kMaxNeighbors);
  if (k <= 0) return 0;
  std::array<float, kMaxNeighbors> best_sq{};
  int found = 0;
  const auto kth = static_cast<std::size_t>(k - 1);
  const auto visit = [&](const VoxelKey& key) {
    const auto it = map_.find(key);
    if (it == map_.end()) return;
    const std::vector<std::uint8_t>* voxel_sources = nullptr;
    if constexpr (kBySource) {
      const auto found_sources = sources_.find(key);
      if (found_sources != sources_.end()) voxel_sources = &found_sources->second;
    }
    const std::span<const Eigen::Vector3f> points = points_of(it->second);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3f& p = points[i];
      const float d = (p - q).squaredNorm();
      if (d > max_distance_sq || (found == k && d >= best_sq[kth]) || !keep(voxel_sources, i)) continue;
      int slot = found < k ? found++ : k - 1;  // insertion sort into the sorted prefix
      while (slot > 0 && best_sq[static_cast<std::size_t>(slot - 1)] > d) {
        best_sq[static_cast<std::size_t>(slot)] = best_sq[static_cast<std::size_t>(slot - 1)];
        out[static_cast<std::size_t>(slot)] = out[static_cast<std::size_t>(slot - 1)];
        --slot;
      }
      best_sq[static_cast<std::size_t>(slot)] = d;
      out[static_cast<std::size_t>(slot)] = p;
    }
  };
  const VoxelKey center = key_of(q);
  visit(center);
  // A neighbour is searched only when its box (a lower bound of its points' squared distance, shrunk a little
  // against rounding) is within the radius and, once k are found, nearer than the k-th best: exact.
  const double inv = 1.0 / voxel_size_;
  const auto size = static_cast<float>(voxel_size_);
  const auto fraction_of = [inv](float coordinate, std::int32_t cell) {
    return static_cast<float>(static_cast<double>(coordinate) * inv - cell);
  };
  const AxisLayers x = axis_layers(fraction_of(q.x(), center.x), size);
  const AxisLayers y = axis_layers(fraction_of(q.y(), center.y), size);
  const AxisLayers z = axis_layers(fraction_of(q.z(), center.z), size);
  const auto shrunk = [](float gap_sq) { return gap_sq * 0.999F - 1e-6F; };
  // From kFirstWithFarSide on every box has a far side, so its bound is at least the smallest far gap's (float
  // sums of non-negative gaps and the shrink are monotone): when that bound is skipped, all of them are.
  const float far_bound = shrunk(std::min({x.gap_sq[2], y.gap_sq[2], z.gap_sq[2]}));
  for (std::size_t i = 0; i < kNeighbourSides.size(); ++i) {
    if (i == kFirstWithFarSide && (far_bound > max_distance_sq || (found == k && far_bound >= best_sq[kth]))) break;
    const auto& [sx, sy, sz] = kNeighbourSides[i];
    const float bound = shrunk(x.gap_sq[sx] + y.gap_sq[sy] + z.gap_sq[sz]);
    if (bound > max_distance_sq || (found == k && bound >= best_sq[kth])) continue;
    visit({center.x + x.offset[sx], center.y + y.offset[sy], center.z + z.offset[sz]});
  }
  return found;
}

std::vector<Eigen::Vector3f> VoxelMap::points() const {
  std::vector<Eigen::Vector3f> all;
  for (const auto& [key, bucket] : map_) {
    const std::span<const Eigen::Vector3f> kept = points_of(bucket);
    all.insert(all.end(), kept.begin(), kept.end());
  }
  return all;
}

std::vector<PointCovariance> VoxelMap::covariances() const {
  std::vector<PointCovariance> all;
  for (const auto& [key, bucket] : map_) {
    const auto it = covariances_.find(key);
    const std::size_t begin = all.size();
    if (it != covariances_.end()) all.insert(all.end(), it->second.begin(), it->second.end());
    all.resize(begin + bucket.count);
  }
  return all;
}

std::vector<std::uint8_t> VoxelMap::sources() const {
  std::vector<std::uint8_t> all;
  for (const auto& [key, bucket] : map_) {
    const auto it = sources_.find(key);
    const std::size_t begin = all.size();
    if (it != sources_.end()) all.insert(all.end(), it->second.begin(), it->second.end());
    all.resize(begin + bucket.count, kNoSource);
  }
  return all;
}

}  // namespace mlidar::slam
