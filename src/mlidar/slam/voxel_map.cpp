#include "mlidar/slam/voxel_map.hpp"

#include <cmath>
#include <stdexcept>

namespace mlidar::slam {

VoxelMap::VoxelMap(double voxel_size, int max_points_per_voxel) : voxel_size_(voxel_size), max_points_(max_points_per_voxel) {
  if (!(voxel_size > 0.0) || max_points_per_voxel < 1) throw std::invalid_argument("VoxelMap: voxel_size must be > 0 and max_points_per_voxel >= 1");
}

VoxelKey VoxelMap::key_of(const Eigen::Vector3f& p) const {
  const double inv = 1.0 / voxel_size_;
  return {static_cast<std::int32_t>(std::floor(p.x() * inv)), static_cast<std::int32_t>(std::floor(p.y() * inv)),
          static_cast<std::int32_t>(std::floor(p.z() * inv))};
}

void VoxelMap::add(std::span<const Eigen::Vector3f> points) {
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    auto& bucket = map_[key_of(p)];
    if (bucket.empty()) bucket.reserve(static_cast<std::size_t>(max_points_));
    if (static_cast<int>(bucket.size()) < max_points_) bucket.push_back(p);
  }
}

void VoxelMap::remove_far(const Eigen::Vector3f& origin, double max_distance) {
  const float limit_sq = static_cast<float>(max_distance * max_distance);
  for (auto it = map_.begin(); it != map_.end();) {
    if ((it->second.front() - origin).squaredNorm() > limit_sq) {
      it = map_.erase(it);
    } else {
      ++it;
    }
  }
}

int VoxelMap::nearest(const Eigen::Vector3f& q, int k, float max_distance_sq, std::array<Eigen::Vector3f, kMaxNeighbors>& out) const {
  k = std::min(k, kMaxNeighbors);
  std::array<float, kMaxNeighbors> best_sq{};
  int found = 0;
  const VoxelKey center = key_of(q);
  for (std::int32_t dx = -1; dx <= 1; ++dx) {
    for (std::int32_t dy = -1; dy <= 1; ++dy) {
      for (std::int32_t dz = -1; dz <= 1; ++dz) {
        const auto it = map_.find({center.x + dx, center.y + dy, center.z + dz});
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
    }
  }
  return found;
}

std::vector<Eigen::Vector3f> VoxelMap::points() const {
  std::vector<Eigen::Vector3f> all;
  for (const auto& [key, bucket] : map_) all.insert(all.end(), bucket.begin(), bucket.end());
  return all;
}

}  // namespace mlidar::slam
