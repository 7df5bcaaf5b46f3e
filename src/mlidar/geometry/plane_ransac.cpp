#include "mlidar/geometry/plane_ransac.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace mlidar {
namespace {

using Index = std::uint32_t;

/// Inliers of `plane` among `candidates` (float distances: the hot loop).
std::vector<Index> collect_inliers(std::span<const Eigen::Vector3f> points, const std::vector<Index>& candidates, const Plane& plane,
                                   double threshold) {
  const Eigen::Vector3f n = plane.normal.cast<float>();
  const float d = static_cast<float>(plane.offset);
  const float limit = static_cast<float>(threshold);
  std::vector<Index> inliers;
  for (const Index i : candidates) {
    if (std::abs(n.dot(points[i]) + d) <= limit) inliers.push_back(i);
  }
  return inliers;
}

std::size_t count_inliers(std::span<const Eigen::Vector3f> points, const std::vector<Index>& candidates, const Eigen::Vector3f& n, float d,
                          float limit) {
  std::size_t count = 0;
  for (const Index i : candidates) count += std::abs(n.dot(points[i]) + d) <= limit ? 1U : 0U;
  return count;
}

/// Hypotheses needed for 99.9 % confidence of one all-inlier sample of 3.
int needed_iterations(std::size_t inliers, std::size_t total, int cap) {
  const double w = static_cast<double>(inliers) / static_cast<double>(total);
  const double all_in = w * w * w;
  if (all_in <= 1e-12) return cap;
  if (all_in >= 1.0) return 1;
  const double k = std::log(1e-3) / std::log(1.0 - all_in);
  return static_cast<int>(std::min(static_cast<double>(cap), std::ceil(k)));
}

/// Best 3-point hypothesis by inlier count (eq 2.1 distance).
Plane best_hypothesis(std::span<const Eigen::Vector3f> points, const std::vector<Index>& candidates, const PlaneRansacConfig& config,
                      std::mt19937_64& rng) {
  std::uniform_int_distribution<std::size_t> pick(0, candidates.size() - 1);
  const float limit = static_cast<float>(config.inlier_distance);
  Plane best;
  std::size_t best_count = 0;
  int needed = config.max_iterations;
  for (int iteration = 0; iteration < needed; ++iteration) {
    const Eigen::Vector3f a = points[candidates[pick(rng)]];
    const Eigen::Vector3f b = points[candidates[pick(rng)]];
    const Eigen::Vector3f c = points[candidates[pick(rng)]];
    Eigen::Vector3f n = (b - a).cross(c - a);
    const float norm = n.norm();
    if (!(norm > 1e-6F)) continue;
    n /= norm;
    const float d = -n.dot(a);
    const std::size_t count = count_inliers(points, candidates, n, d, limit);
    if (count > best_count) {
      best_count = count;
      best = {n.cast<double>(), static_cast<double>(d)};
      needed = needed_iterations(best_count, candidates.size(), config.max_iterations);
    }
  }
  return best;
}

void check(const PlaneRansacConfig& config, std::size_t size) {
  if (!(config.inlier_distance > 0.0) || config.max_iterations < 1 || config.min_inliers < 3 || config.max_planes < 1 ||
      config.refine_passes < 0)
    throw std::invalid_argument("extract_planes: config out of range");
  if (size >= std::numeric_limits<Index>::max()) throw std::invalid_argument("extract_planes: 2^32 points or more");
}

}  // namespace

std::vector<PlaneSegment> extract_planes(std::span<const Eigen::Vector3f> points, const PlaneRansacConfig& config) {
  check(config, points.size());
  std::vector<Index> remaining;
  remaining.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].allFinite()) remaining.push_back(static_cast<Index>(i));
  }
  std::mt19937_64 rng(config.seed);
  std::vector<PlaneSegment> planes;
  while (static_cast<int>(planes.size()) < config.max_planes && remaining.size() >= config.min_inliers) {
    const Plane hypothesis = best_hypothesis(points, remaining, config, rng);
    PlaneSegment segment;
    segment.inliers = collect_inliers(points, remaining, hypothesis, config.inlier_distance);
    for (int pass = 0; pass < config.refine_passes && segment.inliers.size() >= 3; ++pass) {
      segment.fit = fit_plane(points, segment.inliers);  // eq 2.2 on the consensus set
      segment.inliers = collect_inliers(points, remaining, segment.fit.plane, config.inlier_distance);
    }
    if (segment.inliers.size() < config.min_inliers) break;
    segment.fit = fit_plane(points, segment.inliers);
    std::vector<Index> rest;
    rest.reserve(remaining.size() - segment.inliers.size());
    std::size_t k = 0;
    for (const Index i : remaining) {  // both ascending: a merge-style difference
      if (k < segment.inliers.size() && segment.inliers[k] == i) {
        ++k;
      } else {
        rest.push_back(i);
      }
    }
    remaining = std::move(rest);
    planes.push_back(std::move(segment));
  }
  return planes;
}

}  // namespace mlidar
