#include "mlidar/calib/coarse_search.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "mlidar/calib/ref_surface.hpp"
#include "mlidar/core/conversions.hpp"

namespace mlidar::calib {
namespace {

/// The plane with the sensor (the origin) on its positive side: n points towards it.
Plane facing_origin(const Plane& plane) { return plane.offset < 0.0 ? plane.flipped() : plane; }

std::vector<Plane> largest_planes(std::span<const Eigen::Vector3f> points, const CoarseSearchConfig& config) {
  const std::vector<Eigen::Vector3f> thinned = voxel_downsample(points, config.voxel_size);
  std::vector<Plane> planes;
  for (const PlaneSegment& segment : extract_planes(thinned, config.ransac)) planes.push_back(facing_origin(segment.fit.plane));
  return planes;
}

std::string offset_label(const Vec3& offset) {
  char text[64];
  std::snprintf(text, sizeof text, ", offset (%.1f, %.1f, %.1f) m", offset.x(), offset.y(), offset.z());
  return text;
}

/// In-plane offsets (perpendicular to n) of the grid, the zero offset first, then row by row.
std::vector<Vec3> in_plane_offsets(const Vec3& n, const CoarseSearchConfig& config) {
  std::vector<Vec3> offsets{Vec3::Zero()};
  if (!(config.xy_radius_m > 0.0) || !(config.xy_step_m > 0.0)) return offsets;
  const Vec3 u = n.unitOrthogonal();
  const Vec3 v = n.cross(u);
  const int half = static_cast<int>(std::floor(config.xy_radius_m / config.xy_step_m));
  for (int i = -half; i <= half; ++i)
    for (int j = -half; j <= half; ++j) {
      const Vec3 offset = (i * u + j * v) * config.xy_step_m;
      if ((i != 0 || j != 0) && offset.norm() <= config.xy_radius_m + 1e-9) offsets.push_back(offset);
    }
  return offsets;
}

/// Starts with the target plane mapped onto the reference ground, yaw swept (and the in-plane grid).
void add_ground_starts(const Plane& ground_ref, const Plane& ground_target, int candidate, const SE3& T_guess,
                       const CoarseSearchConfig& config, std::vector<StartPose>& starts) {
  const Quat R_align = Quat::FromTwoVectors(ground_target.normal, ground_ref.normal);
  // n_r . (R q + t) + d_r = 0 for every q on the target plane needs n_r . t = d_t - d_r.
  const Vec3& n = ground_ref.normal;
  const Vec3 t_guess = T_guess.translation();
  const Vec3 t = t_guess + n * (ground_target.offset - ground_ref.offset - n.dot(t_guess));
  const std::vector<Vec3> offsets = in_plane_offsets(n, config);
  const int steps = static_cast<int>(std::lround(360.0 / config.yaw_step_deg));
  for (const Vec3& offset : offsets)
    for (int k = 0; k < steps; ++k) {
      const double yaw_deg = k * config.yaw_step_deg;
      const Quat R = Quat(Eigen::AngleAxisd(deg_to_rad(yaw_deg), n)) * R_align;
      std::string label = "ground plane " + std::to_string(candidate) + ", yaw " + std::to_string(std::lround(yaw_deg)) + " deg";
      if (offsets.size() > 1) label += offset_label(offset);
      starts.push_back({SE3(R.normalized(), t + offset), std::move(label)});
    }
}

void add_axis_starts(const SE3& T_guess, const CoarseSearchConfig& config, std::vector<StartPose>& starts) {
  const char* axis_names[3] = {"roll", "pitch", "yaw"};
  const int steps = static_cast<int>(std::lround(360.0 / config.fallback_step_deg));
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 1; k < steps; ++k) {
      const double angle_deg = k * config.fallback_step_deg;
      const Quat offset(Eigen::AngleAxisd(deg_to_rad(angle_deg), Vec3::Unit(axis)));
      starts.push_back({SE3(T_guess.rotation() * offset, T_guess.translation()),
                        "guess " + std::string(axis_names[axis]) + " +" + std::to_string(std::lround(angle_deg)) + " deg"});
    }
  }
}

}  // namespace

std::optional<Plane> reference_ground(std::span<const Eigen::Vector3f> ref, const CoarseSearchConfig& config) {
  const double min_cos = std::cos(deg_to_rad(config.ref_ground_tilt_deg));
  for (const Plane& plane : largest_planes(ref, config))
    if (plane.normal.z() >= min_cos) return plane;
  return std::nullopt;
}

std::vector<StartPose> coarse_starts(std::span<const Eigen::Vector3f> ref, std::span<const Eigen::Vector3f> target, const SE3& T_guess,
                                     const CoarseSearchConfig& config) {
  std::vector<StartPose> starts;
  const std::optional<Plane> ground_ref = reference_ground(ref, config);
  if (ground_ref) {
    const std::vector<Plane> target_planes = largest_planes(target, config);
    const int candidates = std::min<int>(config.target_ground_candidates, static_cast<int>(target_planes.size()));
    for (int i = 0; i < candidates; ++i) add_ground_starts(*ground_ref, target_planes[i], i + 1, T_guess, config, starts);
  }
  if (starts.empty()) add_axis_starts(T_guess, config, starts);
  return starts;
}

}  // namespace mlidar::calib
