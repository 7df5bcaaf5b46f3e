#include "mlidar/calib/ground_up.hpp"

#include <cmath>

#include "mlidar/geometry/plane_ransac.hpp"

namespace mlidar::calib {

std::optional<Vec3> ground_up(std::span<const Eigen::Vector3f> points, const Vec3& prior_up, const GroundUpConfig& config) {
  PlaneRansacConfig ransac;
  ransac.inlier_distance = config.inlier_distance_m;
  ransac.min_inliers = config.min_inliers;
  ransac.max_planes = 4;
  const Vec3 prior = prior_up.normalized();
  std::optional<Vec3> best;
  std::size_t best_count = 0;
  for (const PlaneSegment& segment : extract_planes(points, ransac)) {
    Plane plane = segment.fit.plane;
    if (plane.normal.dot(prior) < 0.0) plane = plane.flipped();  // normal towards the prior's up
    const bool near_prior = plane.normal.dot(prior) >= std::cos(config.max_angle_rad);
    const bool below_sensor = plane.offset >= config.min_below_m;  // signed distance of the origin
    if (near_prior && below_sensor && segment.inliers.size() > best_count) {
      best = plane.normal.normalized();
      best_count = segment.inliers.size();
    }
  }
  return best;
}

Quat align_up(const Quat& R_g_lidar, const Vec3& up_lidar) {
  const Quat correction = Quat::FromTwoVectors(R_g_lidar * up_lidar.normalized(), Vec3::UnitZ());
  return (correction * R_g_lidar).normalized();
}

}  // namespace mlidar::calib
