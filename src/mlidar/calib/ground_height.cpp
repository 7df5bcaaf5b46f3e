#include "mlidar/calib/ground_height.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/median.hpp"

namespace mlidar::calib {
namespace {

/// Finite points within max_range_m of their own sensor, moved by T.
std::vector<Eigen::Vector3f> near_points(const Scan& scan, const SE3& T, double max_range_m) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(scan.points.size());
  const float max_sq = static_cast<float>(max_range_m * max_range_m);
  for (const Eigen::Vector3f& p : scan.points) {
    if (p.allFinite() && p.squaredNorm() <= max_sq) out.push_back(T * p);
  }
  return out;
}

/// The best-supported plane near-perpendicular to `axis` with `sensor` on its
/// positive side, oriented that way (the ground seen from above).
std::optional<PlaneSegment> ground_plane(std::span<const Eigen::Vector3f> points, const Vec3& sensor, const Vec3& axis,
                                         const GroundHeightConfig& config) {
  const double min_cos = std::cos(deg_to_rad(config.max_tilt_deg));
  for (PlaneSegment& segment : extract_planes(points, config.ransac)) {  // most supported first
    if (std::abs(segment.fit.plane.normal.dot(axis)) < min_cos) continue;
    if (segment.fit.plane.signed_distance(sensor) < 0.0) segment.fit.plane = segment.fit.plane.flipped();
    return segment;
  }
  return std::nullopt;
}

}  // namespace

std::optional<double> ground_height_shift(const Scan& scan_a, const Scan& scan_b, const SE3& T_a_b, const Vec3& axis_a,
                                          const GroundHeightConfig& config) {
  const Vec3 axis = axis_a.normalized();
  const auto points_a = near_points(scan_a, SE3::identity(), config.max_range_m);
  const auto points_b = near_points(scan_b, T_a_b, config.max_range_m);
  const auto ground_a = ground_plane(points_a, Vec3::Zero(), axis, config);
  const auto ground_b = ground_plane(points_b, T_a_b.translation(), axis, config);
  if (!ground_a || !ground_b) return std::nullopt;
  const Plane& plane_a = ground_a->fit.plane;
  if (plane_a.normal.dot(ground_b->fit.plane.normal) < 0.0) return std::nullopt;  // not the same surface
  // n_a.(c_b + s axis) + d_a = 0.
  return -plane_a.signed_distance(ground_b->fit.centroid) / plane_a.normal.dot(axis);
}

GroundHeightResult height_from_ground(std::span<const Scan> scans_a, std::span<const Scan> scans_b, const SE3& T_a_b, const Vec3& axis_a,
                                      const GroundHeightConfig& config) {
  if (scans_a.size() != scans_b.size()) throw std::invalid_argument("height_from_ground: scan counts differ");
  std::vector<double> shifts;
  for (std::size_t i = 0; i < scans_a.size(); ++i) {
    if (const auto s = ground_height_shift(scans_a[i], scans_b[i], T_a_b, axis_a, config)) shifts.push_back(*s);
  }
  GroundHeightResult result{T_a_b, shifts.size(), 0.0, 0.0};
  if (shifts.empty()) return result;
  result.shift_m = upper_median(shifts);
  std::vector<double> deviations;
  for (const double s : shifts) deviations.push_back(std::abs(s - result.shift_m));
  result.spread_m = 1.4826 * upper_median(deviations);
  result.T_a_b = SE3(T_a_b.rotation(), T_a_b.translation() + result.shift_m * axis_a.normalized());
  return result;
}

}  // namespace mlidar::calib
