#include "mlidar/slam/map_consistency.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "mlidar/core/median.hpp"
#include "mlidar/slam/map_matcher.hpp"

namespace mlidar::slam {
namespace {

constexpr int kNeighbors = 5;
constexpr float kRadiusSq = 1.0F;
constexpr double kPlanarity = 0.1;  ///< smallest over middle eigenvalue of the neighbours' covariance, at most
constexpr double kMinSpreadSq = 0.01;  ///< their variance along the second direction, at least (m^2): 10 cm across

/// |n^T (p - c)| for the plane through `neighbors` (their mean c, normal n), none when they are not planar.
std::optional<double> plane_distance(const Eigen::Vector3f& p, const std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors>& neighbors) {
  Neighbourhood hood;
  if (!fit_neighbourhood(neighbors, kNeighbors, hood)) return std::nullopt;
  const Vec3& eigenvalues = hood.eigen.eigenvalues();
  // Planar, and spread across in both directions: 5 points along one scan line fit any plane through that line.
  if (!(eigenvalues(0) <= kPlanarity * eigenvalues(1)) || eigenvalues(1) < kMinSpreadSq) return std::nullopt;
  return std::abs(hood.eigen.eigenvectors().col(0).dot(p.cast<double>() - hood.mean));
}

}  // namespace

double consistency_ratio(const std::vector<SourceConsistency>& all, std::size_t i) {
  const SourceConsistency& c = all.at(i);
  if (c.self_planes == 0 || c.cross_planes == 0) return 0.0;
  double noise_m = 0.0;
  for (const SourceConsistency& other : all)
    if (other.self_planes > 0) noise_m = std::max(noise_m, other.self_m);
  return noise_m > 0.0 ? c.cross_m / noise_m : 0.0;
}

std::vector<SourceConsistency> map_consistency(const VoxelMap& map, std::size_t sources, std::size_t samples) {
  const std::vector<Eigen::Vector3f> points = map.points();
  const std::vector<std::uint8_t> of_point = map.sources();
  std::vector<SourceConsistency> out;
  for (std::size_t j = 0; j < sources && j < VoxelMap::kNoSource; ++j) {
    const auto source = static_cast<std::uint8_t>(j);
    std::vector<std::size_t> mine;
    for (std::size_t i = 0; i < points.size(); ++i)
      if (of_point[i] == source) mine.push_back(i);
    if (mine.empty()) continue;
    const std::size_t stride = std::max<std::size_t>(1, mine.size() / std::max<std::size_t>(samples, 1));
    std::vector<double> self, cross;
    std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors> neighbors{};
    for (std::size_t s = 0; s < mine.size(); s += stride) {
      const Eigen::Vector3f& p = points[mine[s]];
      // Its own LiDAR's: the point itself comes first (distance 0) and is left out.
      if (map.nearest_by_source(p, kNeighbors + 1, kRadiusSq, source, true, neighbors) == kNeighbors + 1) {
        std::rotate(neighbors.begin(), neighbors.begin() + 1, neighbors.begin() + kNeighbors + 1);
        if (const auto d = plane_distance(p, neighbors)) self.push_back(*d);
      }
      if (map.nearest_by_source(p, kNeighbors, kRadiusSq, source, false, neighbors) == kNeighbors)
        if (const auto d = plane_distance(p, neighbors)) cross.push_back(*d);
    }
    SourceConsistency c;
    c.source = source;
    c.self_planes = self.size();
    c.cross_planes = cross.size();
    if (!self.empty()) c.self_m = median(self);
    if (!cross.empty()) c.cross_m = median(cross);
    out.push_back(c);
  }
  return out;
}

}  // namespace mlidar::slam
