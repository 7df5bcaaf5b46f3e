#include "mlidar/slam/scan_to_map.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Eigenvalues>

#include "mlidar/slam/map_matcher.hpp"
#include "mlidar/slam/residuals.hpp"

namespace mlidar::slam {
namespace {

/// Sums of one Gauss-Newton linearisation.
struct NormalEquations {
  Mat6 H = Mat6::Zero();
  Vec6 g = Vec6::Zero();
  double residual_sum = 0.0;
  std::size_t planes = 0;
  std::size_t edges = 0;

  /// One scalar row (plane_row), weight w.
  void add(const PlaneRow& row, double w) {
    H.noalias() += (w * row.jacobian) * row.jacobian.transpose();
    g.noalias() += (w * row.residual) * row.jacobian;
  }
  NormalEquations& operator+=(const NormalEquations& o) {
    H += o.H;
    g += o.g;
    residual_sum += o.residual_sum;
    planes += o.planes;
    edges += o.edges;
    return *this;
  }
};

/// A feature's last map search: where it was (world) and what it found.
template <typename Model>
struct CachedMatch {
  Vec3 where = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  ///< NaN: never searched
  std::optional<Model> model;
};

/// The map correspondences of every feature across iterations: a feature is
/// searched again only once it has moved more than the rematch distance from
/// where it was last searched (near convergence the pose moves millimetres and
/// the same map neighbours come back); the residual is always re-evaluated.
struct MatchCache {
  std::vector<CachedMatch<MapLine>> edges;
  std::vector<CachedMatch<PlaneCoefficients>> planes;
};

struct Matcher {
  const VoxelMap& edge_map;
  const VoxelMap& plane_map;
  const SE3& T;
  const RegistrationConfig& config;
  float neighborhood_sq;  ///< squared search radius for the map neighbours
  double max_residual_m;  ///< correspondences with a larger |r| are rejected
  double huber_delta;
  double rematch_sq;           ///< squared rematch distance
  MatchCache& cache;           ///< each feature's entry is touched by one task only
  std::span<float> residuals;  ///< |r| per query (edges, then planes), NaN when unmatched

  template <typename Model, typename Search>
  const std::optional<Model>& lookup(CachedMatch<Model>& cached, const Vec3& q, Search search) const {
    if (!((q - cached.where).squaredNorm() <= rematch_sq)) {
      cached.where = q;
      cached.model = search();
    }
    return cached.model;
  }

  void plane(std::size_t i, const Eigen::Vector3f& p, NormalEquations& eq) const {
    residuals[cache.edges.size() + i] = std::numeric_limits<float>::quiet_NaN();
    const Vec3 q = T * Vec3(p.cast<double>());
    const std::optional<PlaneCoefficients>& plane =
        lookup(cache.planes[i], q, [&] { return match_plane(plane_map, q, neighborhood_sq, config); });
    if (!plane) return;
    // Eq 4.7 as its equivalent scalar row (residuals.hpp).
    const PlaneRow row = plane_row(*plane, q);
    const double norm = std::abs(row.residual);
    if (norm > max_residual_m) return;
    eq.add(row, huber_weight(norm, huber_delta));
    eq.residual_sum += norm;
    residuals[cache.edges.size() + i] = static_cast<float>(norm);
    ++eq.planes;
  }

  void edge(std::size_t i, const Eigen::Vector3f& p, NormalEquations& eq) const {
    residuals[i] = std::numeric_limits<float>::quiet_NaN();
    const Vec3 q = T * Vec3(p.cast<double>());
    const std::optional<MapLine>& line = lookup(cache.edges[i], q, [&] { return match_line(edge_map, q, neighborhood_sq, config); });
    if (!line) return;
    // Eq 4.8: the two perpendicular planes through the line, one scalar row each.
    const EdgePlanes planes = edge_planes(line->point, line->direction, q);
    const PlaneRow first = plane_row(planes.first, q), second = plane_row(planes.second, q);
    const double norm = std::hypot(first.residual, second.residual);
    if (norm > max_residual_m) return;
    const double w = huber_weight(norm, huber_delta);
    eq.add(first, w);
    eq.add(second, w);
    eq.residual_sum += norm;
    residuals[i] = static_cast<float>(norm);
    ++eq.edges;
  }
};

NormalEquations linearise(std::span<const Eigen::Vector3f> edges, std::span<const Eigen::Vector3f> planes, const Matcher& matcher) {
  const std::size_t total = edges.size() + planes.size();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, total, 256), NormalEquations{},
      [&](const tbb::blocked_range<std::size_t>& range, NormalEquations eq) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          if (i < edges.size()) {
            matcher.edge(i, edges[i], eq);
          } else {
            matcher.plane(i - edges.size(), planes[i - edges.size()], eq);
          }
        }
        return eq;
      },
      [](NormalEquations a, const NormalEquations& b) { return a += b; });
}

/// Degeneracy at the solution. Early iterations, far from it, may match mostly
/// one surface (the ground), so this is judged once, at the end: the
/// correction from `initial` loses its translation along the weak direction.
void keep_initial_along_weak_translation(const SE3& initial, double threshold, RegistrationResult& result) {
  // Translation block of H: sum w J_t^T J_t = sum w n n^T over the residual normals.
  const Eigen::SelfAdjointEigenSolver<Mat3> translation(result.hessian.topLeftCorner<3, 3>());
  const Vec3 spread = translation.eigenvalues();
  result.translation_observability = spread(2) > 0.0 ? spread(0) / spread(2) : 0.0;
  result.degenerate = result.translation_observability < threshold;
  if (!result.degenerate) return;
  Vec6 correction = (result.T_world_base * initial.inverse()).log();
  const Vec3 weak = translation.eigenvectors().col(0);
  result.weak_translation = weak;
  correction.head<3>() -= weak * weak.dot(correction.head<3>());
  result.T_world_base = SE3::exp(correction) * initial;
}

}  // namespace

RegistrationResult register_scan_to_map(std::span<const Eigen::Vector3f> edges_in, std::span<const Eigen::Vector3f> planes_in,
                                        const VoxelMap& edge_map, const VoxelMap& plane_map, const SE3& initial,
                                        double max_correspondence_m, const RegistrationConfig& config, const MotionDeskew* motion) {
  // With a MotionDeskew the features are copied and deskewed again as the estimate moves.
  std::vector<Eigen::Vector3f> edges_copy, planes_copy;
  if (motion != nullptr) {
    edges_copy.assign(edges_in.begin(), edges_in.end());
    planes_copy.assign(planes_in.begin(), planes_in.end());
  }
  const std::span<const Eigen::Vector3f> edges_base = motion != nullptr ? std::span<const Eigen::Vector3f>(edges_copy) : edges_in;
  const std::span<const Eigen::Vector3f> planes_base = motion != nullptr ? std::span<const Eigen::Vector3f>(planes_copy) : planes_in;
  RegistrationResult result;
  if (motion != nullptr) result.velocity_used = motion->used;
  result.T_world_base = initial;
  result.queries = edges_base.size() + planes_base.size();
  result.residuals_m.assign(result.queries, std::numeric_limits<float>::quiet_NaN());
  const double radius = std::max(max_correspondence_m, config.neighborhood_radius_m);
  const auto neighborhood_sq = static_cast<float>(radius * radius);
  MatchCache cache{std::vector<CachedMatch<MapLine>>(edges_base.size()), std::vector<CachedMatch<PlaneCoefficients>>(planes_base.size())};
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    const double rematch_sq = config.rematch_distance_m * config.rematch_distance_m;
    const Matcher matcher{edge_map,   plane_map, result.T_world_base, config, neighborhood_sq, max_correspondence_m, config.huber_delta_m,
                          rematch_sq, cache,     result.residuals_m};
    const NormalEquations eq = linearise(edges_base, planes_base, matcher);
    result.iterations = iteration + 1;
    result.plane_matches = eq.planes;
    result.edge_matches = eq.edges;
    result.hessian = eq.H;
    if (eq.planes + eq.edges < 6) return result;
    result.mean_residual_m = eq.residual_sum / static_cast<double>(eq.planes + eq.edges);
    const Vec6 delta = eq.H.ldlt().solve(-eq.g);
    if (!delta.allFinite()) return result;
    result.T_world_base = SE3::exp(delta) * result.T_world_base;
    if (delta.head<3>().norm() < config.convergence_translation_m && delta.tail<3>().norm() < config.convergence_rotation_rad) {
      result.converged = true;
      break;
    }
    if (motion != nullptr) {
      // Eq 4.12 again with the velocity this estimate implies.
      const BodyVelocity measured = BodyVelocity::from_relative_pose(motion->T_world_previous.inverse() * result.T_world_base, motion->dt);
      redeskew(motion->edge_times, *result.velocity_used, measured, edges_copy);
      redeskew(motion->plane_times, *result.velocity_used, measured, planes_copy);
      result.velocity_used = measured;
    }
  }
  result.eigenvalues = Eigen::SelfAdjointEigenSolver<Mat6>(result.hessian).eigenvalues();
  keep_initial_along_weak_translation(initial, config.degeneracy_threshold, result);
  return result;
}

}  // namespace mlidar::slam
