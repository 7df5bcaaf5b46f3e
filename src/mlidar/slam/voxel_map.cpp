#include "mlidar/slam/voxel_map.hpp"

#include <cmath>
#include <stdexcept>

namespace mlidar::slam {

VoxelMap::VoxelMap(double voxel_size, int max_points_per_voxel) : voxel_size_(voxel_size), max_points_(max_points_per_voxel) {
  if (!(voxel_size > 0.0) || max_points_per_voxel < 1)
    throw std::invalid_argument("VoxelMap: voxel_size must be > 0 and max_points_per_voxel >= 1");
}

void VoxelMap::insert(const Eigen::Vector3f& p, const PointCovariance* covariance, std::uint8_t source) {
  if (!p.allFinite()) return;
  const VoxelKey key = key_of(p);
  auto& bucket = map_[key];
  if (bucket.empty()) bucket.reserve(static_cast<std::size_t>(max_points_));
  if (static_cast<int>(bucket.size()) >= max_points_) return;
  if (covariance != nullptr) {
    auto& kept = covariances_[key];
    kept.resize(bucket.size());  // points added without a covariance before this one: zero
    kept.push_back(*covariance);
  }
  if (source != kNoSource) {
    auto& kept = sources_[key];
    kept.resize(bucket.size(), kNoSource);
    kept.push_back(source);
  }
  bucket.push_back(p);
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
    if ((it->second.front() - origin).squaredNorm() > limit_sq) {
      covariances_.erase(it->first);
      sources_.erase(it->first);
      it = map_.erase(it);
    } else {
      ++it;
    }
  }
}

namespace {

/// One of the 27 voxels around a query and a lower bound of its points' squared distance from it.
struct NearbyVoxel {
  float bound_sq;
  std::int8_t dx, dy, dz;
};

/// Squared gap along one axis from a query at `fraction` (in [0, 1) voxels) of its voxel to the neighbour `offset` away.
float axis_gap_sq(float fraction, int offset, float size) {
  const float gap = offset < 0 ? fraction * size : offset > 0 ? (1.0F - fraction) * size : 0.0F;
  return gap * gap;
}

}  // namespace

int VoxelMap::nearest(const Eigen::Vector3f& q, int k, float max_distance_sq, std::array<Eigen::Vector3f, kMaxNeighbors>& out) const {
  k = std::min(k, kMaxNeighbors);
  if (k <= 0) return 0;
  std::array<float, kMaxNeighbors> best_sq{};
  int found = 0;
  const VoxelKey center = key_of(q);
  // Visit the 27 voxels nearest-box first and skip those that cannot hold a
  // point nearer than the radius or the k-th best so far (exact: the bound is
  // the distance to the voxel's box, shrunk a little against rounding).
  const double inv = 1.0 / voxel_size_;
  const auto size = static_cast<float>(voxel_size_);
  const auto fraction_of = [inv](float coordinate, std::int32_t cell) {
    return static_cast<float>(static_cast<double>(coordinate) * inv - cell);
  };
  const Eigen::Vector3f fraction(fraction_of(q.x(), center.x), fraction_of(q.y(), center.y), fraction_of(q.z(), center.z));
  std::array<NearbyVoxel, 27> order{};
  int voxels = 0;
  for (int dx = -1; dx <= 1; ++dx) {
    const float gx = axis_gap_sq(fraction.x(), dx, size);
    for (int dy = -1; dy <= 1; ++dy) {
      const float gxy = gx + axis_gap_sq(fraction.y(), dy, size);
      for (int dz = -1; dz <= 1; ++dz) {
        const float bound = (gxy + axis_gap_sq(fraction.z(), dz, size)) * 0.999F - 1e-6F;
        if (bound > max_distance_sq) continue;
        int slot = voxels++;
        while (slot > 0 && order[static_cast<std::size_t>(slot - 1)].bound_sq > bound) {
          order[static_cast<std::size_t>(slot)] = order[static_cast<std::size_t>(slot - 1)];
          --slot;
        }
        order[static_cast<std::size_t>(slot)] = {bound, static_cast<std::int8_t>(dx), static_cast<std::int8_t>(dy),
                                                 static_cast<std::int8_t>(dz)};
      }
    }
  }
  for (int v = 0; v < voxels; ++v) {
    const NearbyVoxel& voxel = order[static_cast<std::size_t>(v)];
    if (found == k && voxel.bound_sq >= best_sq[static_cast<std::size_t>(k - 1)]) break;
    const auto it = map_.find({center.x + voxel.dx, center.y + voxel.dy, center.z + voxel.dz});
    if (it == map_.end()) continue;
    for (const auto& p : it->second) {
      const float d = (p - q).squaredNorm();
      if (d > max_distance_sq || (found == k && d >= best_sq[static_cast<std::size_t>(k - 1)])) continue;
      int slot = found < k ? found++ : k - 1;  // insertion sort into the sorted prefix
      while (slot > 0 && best_sq[static_cast<std::size_t>(slot - 1)] > d) {
        best_sq[static_cast<std::size_t>(slot)] = best_sq[static_cast<std::size_t>(slot - 1)];
        out[static_cast<std::size_t>(slot)] = out[static_cast<std::size_t>(slot - 1)];
        --slot;
      }
      best_sq[static_cast<std::size_t>(slot)] = d;
      out[static_cast<std::size_t>(slot)] = p;
    }
  }
  return found;
}

std::vector<Eigen::Vector3f> VoxelMap::points() const {
  std::vector<Eigen::Vector3f> all;
  for (const auto& [key, bucket] : map_) all.insert(all.end(), bucket.begin(), bucket.end());
  return all;
}

std::vector<PointCovariance> VoxelMap::covariances() const {
  std::vector<PointCovariance> all;
  for (const auto& [key, bucket] : map_) {
    const auto it = covariances_.find(key);
    const std::size_t begin = all.size();
    if (it != covariances_.end()) all.insert(all.end(), it->second.begin(), it->second.end());
    all.resize(begin + bucket.size());
  }
  return all;
}

std::vector<std::uint8_t> VoxelMap::sources() const {
  std::vector<std::uint8_t> all;
  for (const auto& [key, bucket] : map_) {
    const auto it = sources_.find(key);
    const std::size_t begin = all.size();
    if (it != sources_.end()) all.insert(all.end(), it->second.begin(), it->second.end());
    all.resize(begin + bucket.size(), kNoSource);
  }
  return all;
}

}  // namespace mlidar::slam
