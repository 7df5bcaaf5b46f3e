#include "mlidar/eval/map_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>

#include "mlidar/geometry/kdtree.hpp"

namespace mlidar::eval {
namespace {

constexpr std::size_t kLeafSize = 24;  // radius queries return many points: wider leaves pay off

/// Interleaves the low 21 bits of x, y, z (Morton / Z-order code).
std::uint64_t morton_code(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  std::uint64_t code = 0;
  for (int bit = 0; bit < 21; ++bit) {
    code |= (static_cast<std::uint64_t>((x >> bit) & 1U) << (3 * bit)) | (static_cast<std::uint64_t>((y >> bit) & 1U) << (3 * bit + 1)) |
            (static_cast<std::uint64_t>((z >> bit) & 1U) << (3 * bit + 2));
  }
  return code;
}

/// The finite points, reordered along a Z-order curve over cells of `cell` metres,
/// so consecutive queries touch nearby memory (the metrics do not depend on order).
std::vector<Eigen::Vector3f> finite_points_in_spatial_order(const std::vector<Eigen::Vector3f>& points, double cell) {
  std::vector<Eigen::Vector3f> finite;
  finite.reserve(points.size());
  Eigen::Vector3f lowest = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  for (const Eigen::Vector3f& point : points) {
    if (!point.allFinite()) continue;
    finite.push_back(point);
    lowest = lowest.cwiseMin(point);
  }
  constexpr double kMaxCell = (1U << 21) - 1;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(finite.size());
  for (std::size_t i = 0; i < finite.size(); ++i) {
    const Eigen::Vector3d cell_index = ((finite[i] - lowest).cast<double>() / cell).cwiseMin(kMaxCell);
    keys[i] = {morton_code(static_cast<std::uint32_t>(cell_index.x()), static_cast<std::uint32_t>(cell_index.y()),
                           static_cast<std::uint32_t>(cell_index.z())),
               static_cast<std::uint32_t>(i)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<Eigen::Vector3f> ordered(finite.size());
  for (std::size_t i = 0; i < keys.size(); ++i) ordered[i] = finite[keys[i].second];
  return ordered;
}

struct LocalSpread {
  double entropy = 0.0;  ///< 1/2 ln |2 pi e Sigma|
  double smallest_variance = 0.0;
};

/// Sample covariance of the neighbours, accumulated relative to the query
/// point (offsets are <= radius, so the sums do not cancel catastrophically).
Eigen::Matrix3d neighbour_covariance(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& query,
                                     const std::vector<Neighbor>& neighbors) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();
  for (const Neighbor& neighbor : neighbors) {
    const Eigen::Vector3d offset = (points[neighbor.index] - query).cast<double>();
    sum += offset;
    sum_outer.noalias() += offset * offset.transpose();
  }
  const double n = static_cast<double>(neighbors.size());
  return (sum_outer - sum * sum.transpose() / n) / (n - 1.0);
}

/// Fills `spread`; returns false when Sigma is not full rank.
bool local_spread(const Eigen::Matrix3d& covariance, LocalSpread& spread) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d& eigenvalues = solver.eigenvalues();  // increasing
  if (!(eigenvalues(0) > 1e-12 * std::max(eigenvalues(2), 1e-300))) return false;
  const double log_two_pi_e = std::log(2.0 * std::numbers::pi * std::numbers::e);
  spread.entropy = 0.5 * (3.0 * log_two_pi_e + std::log(eigenvalues(0)) + std::log(eigenvalues(1)) + std::log(eigenvalues(2)));
  spread.smallest_variance = eigenvalues(0);
  return true;
}

}  // namespace

MapMetrics compute_map_metrics(const std::vector<Eigen::Vector3f>& points, const MapMetricsOptions& options) {
  if (!(options.radius > 0.0) || !std::isfinite(options.radius))
    throw std::invalid_argument("map metrics: radius must be a finite number > 0");
  if (options.min_neighbors < 4) throw std::invalid_argument("map metrics: min_neighbors must be >= 4");
  if (points.size() >= std::numeric_limits<std::uint32_t>::max()) throw std::invalid_argument("map metrics: too many points");
  const KdTree3f tree(finite_points_in_spatial_order(points, options.radius), kLeafSize);
  const std::vector<Eigen::Vector3f>& cloud = tree.points();
  const auto radius = static_cast<float>(options.radius);

  MapMetrics metrics;
  metrics.points = points.size();
  double sum_entropy = 0.0;
  double sum_plane_variance = 0.0;
  std::vector<Neighbor> neighbors;
  for (const Eigen::Vector3f& query : cloud) {
    tree.radius_search_unsorted(query, radius, neighbors);
    if (neighbors.size() < options.min_neighbors) continue;
    LocalSpread spread;
    if (!local_spread(neighbour_covariance(cloud, query, neighbors), spread)) continue;
    sum_entropy += spread.entropy;
    sum_plane_variance += spread.smallest_variance;
    ++metrics.points_used;
  }
  const double used = static_cast<double>(metrics.points_used);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  metrics.mean_map_entropy = metrics.points_used > 0 ? sum_entropy / used : nan;
  metrics.mean_plane_variance = metrics.points_used > 0 ? sum_plane_variance / used : nan;
  return metrics;
}

CovarianceTraceStats summarize_traces(std::vector<double> traces) {
  CovarianceTraceStats stats;
  stats.count = traces.size();
  if (traces.empty()) {
    stats.mean = stats.p50 = stats.p95 = stats.max = std::numeric_limits<double>::quiet_NaN();
    return stats;
  }
  std::sort(traces.begin(), traces.end());
  const auto rank = [&](double q) {  // nearest rank: the smallest value with at least q of the values at or below it
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(traces.size())));
    return traces[std::max<std::size_t>(k, 1) - 1];
  };
  double sum = 0.0;
  for (const double t : traces) sum += t;
  stats.mean = sum / static_cast<double>(traces.size());
  stats.p50 = rank(0.5);
  stats.p95 = rank(0.95);
  stats.max = traces.back();
  return stats;
}

}  // namespace mlidar::eval
