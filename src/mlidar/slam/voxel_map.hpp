#pragma once
// Voxel-hashed local map (tsl::robin_map from integer voxel coordinates to a
// small bounded bucket of points), the structure of KISS-ICP's VoxelHashMap:
// insertion O(1), a k-nearest query scans the query's voxel, then those of
// its 26 neighbours (faces, edges, corners) whose box can still beat the k-th best.
// Not thread-safe for writes; const queries may run concurrently.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <cmath>

#include <tsl/robin_map.h>
#include <Eigen/Core>

#include "mlidar/slam/point_uncertainty.hpp"

namespace mlidar::slam {

struct VoxelKey {
  std::int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelKey&) const = default;
};

/// The cube of edge 1 / inv_edge that holds p (floor of each coordinate times inv_edge).
inline VoxelKey voxel_key(const Eigen::Vector3f& p, double inv_edge) {
  return {static_cast<std::int32_t>(std::floor(p.x() * inv_edge)), static_cast<std::int32_t>(std::floor(p.y() * inv_edge)),
          static_cast<std::int32_t>(std::floor(p.z() * inv_edge))};
}

struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& key) const {
    // Teschner et al. 2003 spatial hash primes.
    return static_cast<std::size_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.x)) * 73856093ULL) ^
                                    (static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.y)) * 19349669ULL) ^
                                    (static_cast<std::uint64_t>(static_cast<std::uint32_t>(key.z)) * 83492791ULL));
  }
};

class VoxelMap {
 public:
  static constexpr int kMaxNeighbors = 8;

  /// voxel_size > 0 metres; max_points_per_voxel >= 1. Throws std::invalid_argument otherwise.
  VoxelMap(double voxel_size, int max_points_per_voxel);

  /// Adds world points; a full voxel ignores new points.
  void add(std::span<const Eigen::Vector3f> points);
  /// The same with each point's covariance (same length; uncertainty-aware mapping), kept for covariances().
  void add(std::span<const Eigen::Vector3f> points, std::span<const PointCovariance> covariances);
  /// Covariant points, with their sources (CovariantPoint::source) kept for sources().
  void add(std::span<const CovariantPoint> points);
  /// Points, each with the index of the LiDAR that saw it (same length), kept for sources().
  void add(std::span<const Eigen::Vector3f> points, std::span<const std::uint8_t> sources);
  /// Drops voxels whose first point lies farther than max_distance from origin.
  void remove_far(const Eigen::Vector3f& origin, double max_distance);

  /// Up to k (<= kMaxNeighbors) stored points nearest to q among the 27
  /// surrounding voxels with squared distance <= max_distance_sq, nearest
  /// first, written to out; returns how many.
  int nearest(const Eigen::Vector3f& q, int k, float max_distance_sq, std::array<Eigen::Vector3f, kMaxNeighbors>& out) const;
  /// The same among the points whose source (kNoSource for one added without) is `source` (same_source) or is not.
  int nearest_by_source(const Eigen::Vector3f& q, int k, float max_distance_sq, std::uint8_t source, bool same_source,
                        std::array<Eigen::Vector3f, kMaxNeighbors>& out) const;

  std::vector<Eigen::Vector3f> points() const;
  /// Each point of points() (same order): its covariance, zero for a point added without one.
  std::vector<PointCovariance> covariances() const;
  /// Each point of points() (same order): the LiDAR index it was added with, kNoSource when added without one.
  std::vector<std::uint8_t> sources() const;
  static constexpr std::uint8_t kNoSource = 255;
  std::size_t voxels() const { return map_.size(); }
  bool empty() const { return map_.empty(); }
  double voxel_size() const { return voxel_size_; }

 private:
  VoxelKey key_of(const Eigen::Vector3f& p) const { return voxel_key(p, 1.0 / voxel_size_); }
  /// Adds p unless it is not finite or its voxel is full; with `covariance` and a `source`, keeps them beside the point.
  void insert(const Eigen::Vector3f& p, const PointCovariance* covariance, std::uint8_t source = kNoSource);
  /// nearest() over the points `keep(voxel sources, index in the voxel)` accepts (voxel sources: looked up only with
  /// kBySource, null when none kept).
  template <bool kBySource, typename Keep>
  int search(const Eigen::Vector3f& q, int k, float max_distance_sq, std::array<Eigen::Vector3f, kMaxNeighbors>& out, const Keep& keep) const;

  double voxel_size_;
  int max_points_;
  /// A voxel's points: pool_[first, first + count).
  struct Bucket {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
  };
  std::span<const Eigen::Vector3f> points_of(const Bucket& bucket) const { return {pool_.data() + bucket.first, bucket.count}; }

  tsl::robin_map<VoxelKey, Bucket, VoxelKeyHash> map_;
  /// Every voxel's points in one array, max_points_ slots per voxel (no allocation per new voxel); slots of removed
  /// voxels are reused.
  std::vector<Eigen::Vector3f> pool_;
  std::vector<std::uint32_t> free_slots_;
  /// Per voxel, the covariances of its first points (a prefix of the bucket's; the rest are zero); only voxels
  /// that received a point with one.
  tsl::robin_map<VoxelKey, std::vector<PointCovariance>, VoxelKeyHash> covariances_;
  /// Per voxel, the LiDAR indices of its first points, likewise (kNoSource for a point added without one).
  tsl::robin_map<VoxelKey, std::vector<std::uint8_t>, VoxelKeyHash> sources_;
};

}  // namespace mlidar::slam
