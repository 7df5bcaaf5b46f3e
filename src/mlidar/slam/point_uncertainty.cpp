#include "mlidar/slam/point_uncertainty.hpp"

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
  std::vector<PointCovariance> out;
  out.reserve(points_base.size());
  for (const Eigen::Vector3f& p : points_base) {
    const Vec3 p_lidar = T_lidar_base * Vec3(p.cast<double>());
    const Mat3 Z = lidar_point_noise(p_lidar, range_sigma_m, angular_sigma_rad);
    out.push_back(PointCovariance::from(point_covariance(T_base_lidar, p_lidar, Z)));  // eq 4.29
  }
  return out;
}

std::vector<CovariantPoint> covariance_voxel_filter(std::span<const CovariantPoint> points, double cube_m, double trace_threshold_m2) {
  if (!(cube_m > 0.0)) throw std::invalid_argument("covariance_voxel_filter: cube edge must be > 0");
  struct Cube {
    double weight_sum = 0.0;  ///< sum of (w - tr Sigma_i) over its points
    Vec3 mean = Vec3::Zero();
    Mat3 covariance = Mat3::Zero();
    double heaviest_weight = -1.0;
    std::uint8_t source = 255;  ///< of the heaviest point
  };
  const double inv = 1.0 / cube_m;
  const auto raw_weight = [trace_threshold_m2](const CovariantPoint& p) {
    return std::max(0.0, trace_threshold_m2 - p.covariance.trace());
  };
  tsl::robin_map<VoxelKey, std::size_t, VoxelKeyHash> index;
  std::vector<Cube> cubes;
  std::vector<std::size_t> cube_of(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto [it, added] = index.try_emplace(voxel_key(points[i].point, inv), cubes.size());
    if (added) cubes.emplace_back();
    cube_of[i] = it->second;
    Cube& cube = cubes[it->second];
    const double weight = raw_weight(points[i]);
    cube.weight_sum += weight;
    if (weight > cube.heaviest_weight) {
      cube.heaviest_weight = weight;
      cube.source = points[i].source;
    }
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    Cube& cube = cubes[cube_of[i]];
    if (!(cube.weight_sum > 0.0)) continue;
    const double w = raw_weight(points[i]) / cube.weight_sum;  // eq 4.30's normalized weight
    cube.mean += w * points[i].point.cast<double>();
    cube.covariance += (w * w) * points[i].covariance.matrix();
  }
  std::vector<CovariantPoint> out;
  out.reserve(cubes.size());
  for (const Cube& cube : cubes)
    if (cube.weight_sum > 0.0) out.push_back({cube.mean.cast<float>(), PointCovariance::from(cube.covariance), cube.source});
  return out;
}

}  // namespace mlidar::slam
