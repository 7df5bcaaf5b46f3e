#include "mlidar/calib/point_to_plane_icp.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace mlidar::calib {
namespace {

/// The weighted normal equations of one Gauss-Newton step.
struct LinearSystem {
  Mat6 H = Mat6::Zero();
  Vec6 b = Vec6::Zero();
  double weighted_sq = 0.0;  ///< sum w r^2
  double inlier_sq = 0.0;    ///< sum r^2 over |r| <= 3c
  std::size_t inliers = 0;
  std::size_t matches = 0;
};

LinearSystem build_system(RefSurface& surface, std::span<const Eigen::Vector3f> source, const SE3& T, const IcpLevel& level) {
  LinearSystem system;
  const Mat3 R = T.rotation_matrix();
  const double max_sq = level.max_correspondence * level.max_correspondence;
  const double c_sq = level.kernel_scale * level.kernel_scale;
  for (const Eigen::Vector3f& p_source : source) {
    const Vec3 p = R * p_source.cast<double>() + T.translation();
    const Neighbor nearest = surface.tree().knn(p.cast<float>(), 1).front();
    if (nearest.distance_sq > max_sq) continue;
    const std::optional<Vec3> normal = surface.normal_at(nearest.index);
    if (!normal) continue;
    const Vec3 q = surface.tree().points()[nearest.index].cast<double>();
    const double r = normal->dot(p - q);
    const double w = 1.0 / (1.0 + r * r / c_sq);  // Cauchy IRLS weight
    Vec6 J;
    J << *normal, p.cross(*normal);
    system.H.noalias() += w * J * J.transpose();
    system.b.noalias() += w * r * J;
    system.weighted_sq += w * r * r;
    if (r * r <= 9.0 * c_sq) {
      system.inlier_sq += r * r;
      ++system.inliers;
    }
    ++system.matches;
  }
  return system;
}

/// The source thinned for one level: voxel filter, then an even stride down to max_points.
std::vector<Eigen::Vector3f> level_points(std::span<const Eigen::Vector3f> source, const IcpLevel& level, std::size_t max_points) {
  std::vector<Eigen::Vector3f> thinned =
      level.voxel_size > 0.0 ? voxel_downsample(source, level.voxel_size) : std::vector<Eigen::Vector3f>(source.begin(), source.end());
  if (thinned.size() <= max_points) return thinned;
  std::vector<Eigen::Vector3f> strided;
  strided.reserve(max_points);
  for (std::size_t k = 0; k < max_points; ++k) strided.push_back(thinned[k * thinned.size() / max_points]);
  return strided;
}

void check_config(const IcpConfig& config) {
  if (config.levels.empty() || config.max_points == 0) throw std::invalid_argument("point_to_plane_icp: no level or no points");
  for (const IcpLevel& level : config.levels)
    if (!(level.max_correspondence > 0.0) || !(level.kernel_scale > 0.0) || level.voxel_size < 0.0)
      throw std::invalid_argument("point_to_plane_icp: distances must be > 0");
}

Mat6 covariance_from(const LinearSystem& system) {
  if (system.matches <= 6) return Mat6::Zero();
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(system.H);
  if (eig.eigenvalues()(0) <= 1e-12 * eig.eigenvalues()(5)) return Mat6::Zero();
  const double s_sq = system.weighted_sq / static_cast<double>(system.matches - 6);
  return s_sq * system.H.inverse();
}

}  // namespace

IcpResult point_to_plane_icp(RefSurface& surface, std::span<const Eigen::Vector3f> source, const SE3& T_ref_source,
                             const IcpConfig& config) {
  check_config(config);
  IcpResult result;
  result.T_ref_source = T_ref_source;
  for (const IcpLevel& level : config.levels) {
    const std::vector<Eigen::Vector3f> points = level_points(source, level, config.max_points);
    LinearSystem system;
    result.converged = false;
    for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
      system = build_system(surface, points, result.T_ref_source, level);
      ++result.iterations;
      if (system.matches < config.min_matches) break;
      const Vec6 delta = system.H.ldlt().solve(-system.b);
      if (!delta.allFinite()) break;
      result.T_ref_source = SE3::exp(delta) * result.T_ref_source;
      if (delta.tail<3>().norm() < config.rotation_tolerance && delta.head<3>().norm() < config.translation_tolerance) {
        result.converged = true;
        break;
      }
    }
    // Statistics at the final pose of this level (the last step moved it).
    system = build_system(surface, points, result.T_ref_source, level);
    result.matches = system.matches;
    result.enough_matches = system.matches >= config.min_matches;
    result.inlier_ratio = points.empty() ? 0.0 : static_cast<double>(system.inliers) / static_cast<double>(points.size());
    result.rmse = system.inliers == 0 ? 0.0 : std::sqrt(system.inlier_sq / static_cast<double>(system.inliers));
    result.information = system.H;
    result.covariance = covariance_from(system);
    if (!result.enough_matches) break;
  }
  return result;
}

}  // namespace mlidar::calib
