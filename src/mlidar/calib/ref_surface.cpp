#include "mlidar/calib/ref_surface.hpp"

#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "mlidar/geometry/plane_fit.hpp"

namespace mlidar::calib {
namespace {

std::int64_t voxel_key(const Eigen::Vector3f& p, double voxel_size) {
  // 21 bits per axis (+-1e6 voxels) is far beyond any LiDAR range.
  constexpr std::int64_t kMask = (std::int64_t{1} << 21) - 1;
  const auto cell = [&](float v) { return static_cast<std::int64_t>(std::floor(v / voxel_size)) & kMask; };
  return (cell(p.x()) << 42) | (cell(p.y()) << 21) | cell(p.z());
}

}  // namespace

std::vector<Eigen::Vector3f> voxel_downsample(std::span<const Eigen::Vector3f> points, double voxel_size) {
  if (!(voxel_size > 0.0)) throw std::invalid_argument("voxel_downsample: voxel_size must be > 0");
  std::unordered_map<std::int64_t, std::size_t> slot_of;
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() > 1e5F) continue;
    const auto [it, inserted] = slot_of.try_emplace(voxel_key(p, voxel_size), sums.size());
    if (inserted) {
      sums.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    sums[it->second] += p.cast<double>();
    ++counts[it->second];
  }
  std::vector<Eigen::Vector3f> out(sums.size());
  for (std::size_t i = 0; i < sums.size(); ++i) out[i] = (sums[i] / counts[i]).cast<float>();
  return out;
}

RefSurface::RefSurface(std::vector<Eigen::Vector3f> points, const SurfaceConfig& config)
    : tree_(std::move(points)), config_(config), state_(tree_.size(), 0), normals_(tree_.size()) {}

std::optional<Vec3> RefSurface::normal_at(std::uint32_t index) {
  if (state_[index] == 0) {
    const std::vector<Neighbor> near = tree_.knn(tree_.points()[index], config_.normal_neighbours);
    const double max_sq = config_.max_neighbour_distance * config_.max_neighbour_distance;
    bool valid = near.size() >= 3 && near.back().distance_sq <= max_sq;
    if (valid) {
      std::vector<std::uint32_t> indices;
      for (const Neighbor& n : near) indices.push_back(n.index);
      const PlaneFit fit = fit_plane(tree_.points(), indices);
      const Vec3& ev = fit.eigenvalues;  // ascending
      valid = ev(1) > config_.min_line_ratio * ev(2) && ev(0) <= config_.max_planarity * ev(1);
      normals_[index] = fit.plane.normal.cast<float>();
    }
    state_[index] = valid ? 1 : 2;
  }
  if (state_[index] == 2) return std::nullopt;
  return normals_[index].cast<double>();
}

Overlap overlap(const KdTree3f& tree_a, std::span<const Eigen::Vector3f> points_b, const SE3& T_a_b, double radius) {
  Overlap result;
  if (tree_a.size() == 0 || points_b.empty()) return result;
  std::vector<Eigen::Vector3f> mapped_b(points_b.size());
  transform_points(T_a_b, points_b, mapped_b);
  const float radius_sq = static_cast<float>(radius * radius);
  std::size_t near_b = 0;
  for (const Eigen::Vector3f& p : mapped_b) near_b += tree_a.knn(p, 1).front().distance_sq < radius_sq ? 1 : 0;
  const KdTree3f tree_b(std::move(mapped_b));
  std::size_t near_a = 0;
  for (const Eigen::Vector3f& p : tree_a.points()) near_a += tree_b.knn(p, 1).front().distance_sq < radius_sq ? 1 : 0;
  result.fraction_b = static_cast<double>(near_b) / static_cast<double>(points_b.size());
  result.fraction_a = static_cast<double>(near_a) / static_cast<double>(tree_a.size());
  return result;
}

}  // namespace mlidar::calib
