#include "mlidar/eval/surface_error.hpp"

#include <cmath>
#include <stdexcept>

#include "mlidar/geometry/kdtree.hpp"

namespace mlidar::eval {

SurfaceError surface_error(const std::vector<Eigen::Vector3f>& points, const std::optional<std::vector<io::UpperCovariance>>& covariances,
                           const io::SurfaceSamples& surfaces, const SurfaceErrorOptions& options) {
  if (covariances && covariances->size() != points.size()) throw std::invalid_argument("surface_error: one covariance per point");
  if (surfaces.points.empty() || surfaces.normals.size() != surfaces.points.size())
    throw std::invalid_argument("surface_error: no surface samples, or not one normal each");
  if (!(options.max_distance_m > 0.0)) throw std::invalid_argument("surface_error: max_distance_m must be positive");
  const KdTree3f tree(surfaces.points);
  const double max_sq = options.max_distance_m * options.max_distance_m;
  SurfaceError out;
  out.points = points.size();
  std::vector<double> distances;
  NormalizedSurfaceError normalized;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const auto nearest = tree.knn(points[i], 1);
    if (nearest.empty() || nearest.front().distance_sq > max_sq) continue;
    const Eigen::Vector3d q = surfaces.points[nearest.front().index].cast<double>();
    const Eigen::Vector3d n = surfaces.normals[nearest.front().index].cast<double>();
    const double d = n.dot(points[i].cast<double>() - q);
    distances.push_back(std::abs(d));
    out.signed_mean_m += d;
    if (!covariances) continue;
    const double variance = n.dot(io::to_matrix((*covariances)[i]) * n);
    if (!(variance > 0.0)) continue;  // no spread along the normal: e is undefined
    const double e = d / std::sqrt(variance);
    ++normalized.count;
    normalized.mean += e;
    normalized.variance += e * e;
    normalized.inside_95 += std::abs(e) <= 1.959964 ? 1.0 : 0.0;
  }
  out.matched = distances.size();
  out.signed_mean_m = out.matched > 0 ? out.signed_mean_m / static_cast<double>(out.matched) : std::nan("");
  out.distance_m = summarize(std::move(distances));
  if (covariances) {
    if (normalized.count > 0) {
      const auto n = static_cast<double>(normalized.count);
      normalized.mean /= n;
      normalized.variance /= n;
      normalized.inside_95 /= n;
    } else {
      normalized.mean = normalized.variance = normalized.inside_95 = std::nan("");
    }
    out.normalized = normalized;
  }
  return out;
}

}  // namespace mlidar::eval
