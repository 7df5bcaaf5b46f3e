#include "mlidar/slam/point_uncertainty.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

#include <tsl/robin_map.h>

#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {

PointCovariance PointCovariance::from(const Mat3& m) {
  PointCovariance c;
  c.upper = {static_cast<float>(m(0, 0)), static_cast<float>(m(0, 1)), static_cast<float>(m(0, 2)),
             static_cast<float>(m(1, 1)), static_cast<float>(m(1, 2)), static_cast<float>(m(2, 2))};
  return c;
}

Mat3 PointCovariance::matrix() const {
  Mat3 m;
  m << upper[0], upper[1], upper[2], upper[1], upper[3], upper[4], upper[2], upper[4], upper[5];
  return m;
}

double PointCovariance::along(const Vec3& n) const {
  const double x = n.x(), y = n.y(), z = n.z();
  return upper[0] * x * x + upper[3] * y * y + upper[5] * z * z + 2.0 * (upper[1] * x * y + upper[2] * x * z + upper[4] * y * z);
}

std::vector<PointCovariance> feature_covariances(std::span<const Eigen::Vector3f> points_base, const UncertainPose& T_base_lidar,
                                                 double range_sigma_m, double angular_sigma_rad) {
  const SE3 T_lidar_base = T_base_lidar.T.inverse();
  const BeamPointCovariance covariance_of(T_base_lidar, range_sigma_m, angular_sigma_rad);  // eq 4.29
  std::vector<PointCovariance> out;
  out.reserve(points_base.size());
  for (const Eigen::Vector3f& p : points_base) out.push_back(PointCovariance::from(covariance_of(T_lidar_base * Vec3(p.cast<double>()))));
  return out;
}

namespace {

/// One cube of eq 4.30 with the raw weights r_i = w - tr(Sigma_i): w_i = r_i / sum r, so its mean is
/// sum(r_i y_i) / sum r and its covariance sum(r_i^2 Sigma_i) / (sum r)^2.
struct Cube {
  double weight_sum = 0.0;
  Vec3 weighted_points = Vec3::Zero();
  std::array<double, 6> weighted_covariance{};  ///< sum r_i^2 Sigma_i, upper triangle as PointCovariance
  double heaviest_weight = -1.0;
  std::uint8_t source = 255;  ///< of the heaviest point
};

}  // namespace

std::vector<CovariantPoint> covariance_voxel_filter(std::span<const CovariantPoint> points, double cube_m, double trace_threshold_m2) {
  if (!(cube_m > 0.0)) throw std::invalid_argument("covariance_voxel_filter: cube edge must be > 0");
  const double inv = 1.0 / cube_m;
  tsl::robin_map<VoxelKey, std::size_t, VoxelKeyHash> index;
  index.reserve(points.size());  // no rehash on the way
  std::vector<Cube> cubes;
  cubes.reserve(points.size());
  for (const CovariantPoint& p : points) {
    const auto [it, added] = index.try_emplace(voxel_key(p.point, inv), cubes.size());
    if (added) cubes.emplace_back();
    Cube& cube = cubes[it->second];
    const double weight = std::max(0.0, trace_threshold_m2 - p.covariance.trace());
    if (weight > cube.heaviest_weight) {
      cube.heaviest_weight = weight;
      cube.source = p.source;
    }
    if (weight == 0.0) continue;
    cube.weight_sum += weight;
    cube.weighted_points += weight * p.point.cast<double>();
    for (std::size_t k = 0; k < 6; ++k) cube.weighted_covariance[k] += weight * weight * static_cast<double>(p.covariance.upper[k]);
  }
  std::vector<CovariantPoint> out;
  out.reserve(cubes.size());
  for (const Cube& cube : cubes) {
    if (!(cube.weight_sum > 0.0)) continue;  // only points with tr(Sigma) >= w
    CovariantPoint merged;
    merged.point = (cube.weighted_points / cube.weight_sum).cast<float>();
    const double scale = 1.0 / (cube.weight_sum * cube.weight_sum);
    for (std::size_t k = 0; k < 6; ++k) merged.covariance.upper[k] = static_cast<float>(scale * cube.weighted_covariance[k]);
    merged.source = cube.source;
    out.push_back(merged);
  }
  return out;
}

}  // namespace mlidar::slam
