#include "mlidar/calib/corner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/LU>

#include "mlidar/core/error.hpp"

namespace mlidar::calib {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// Smallest angle (deg) between the planes as lines of normals, in [0, 90].
double smallest_line_angle_deg(const std::array<Plane, 3>& planes) {
  double largest_cos = 0.0;
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) largest_cos = std::max(largest_cos, std::abs(planes[i].normal.dot(planes[j].normal)));
  }
  return std::acos(std::min(1.0, largest_cos)) / kDeg;
}

/// Distance from `point` to the nearest of `indices`.
double nearest_distance(std::span<const Eigen::Vector3f> points, const std::vector<std::uint32_t>& indices, const Vec3& point) {
  double best = std::numeric_limits<double>::infinity();
  for (const std::uint32_t i : indices) best = std::min(best, (points[i].cast<double>() - point).squaredNorm());
  return std::sqrt(best);
}

/// Each finite point within the inlier band goes to its nearest plane.
std::array<std::vector<std::uint32_t>, 3> assign_points_impl(std::span<const Eigen::Vector3f> points, const std::array<Plane, 3>& planes,
                                                             double band) {
  std::array<std::vector<std::uint32_t>, 3> inliers;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!points[k].allFinite()) continue;
    const Vec3 p = points[k].cast<double>();
    int best = -1;
    double best_distance = band;
    for (int i = 0; i < 3; ++i) {
      const double d = std::abs(planes[i].signed_distance(p));
      if (d <= best_distance) {
        best_distance = d;
        best = i;
      }
    }
    if (best >= 0) inliers[best].push_back(static_cast<std::uint32_t>(k));
  }
  return inliers;
}

struct Candidate {
  std::array<int, 3> segments{};
  std::size_t support = 0;
  bool angles_ok = false;
  bool near_clouds = false;
  int rank() const { return (angles_ok ? 2 : 0) + (near_clouds ? 1 : 0); }
};

}  // namespace

Vec3 corner_point(const std::array<Plane, 3>& planes) {
  Mat3 normals;
  Vec3 offsets;
  for (int i = 0; i < 3; ++i) {
    normals.row(i) = planes[i].normal.transpose();
    offsets(i) = planes[i].offset;
  }
  return normals.partialPivLu().solve(-offsets);  // eq 2.3
}

std::array<int, 3> orient_and_order(std::array<Plane, 3>& planes, const Vec3& up) {
  // Eq 2.4 asks a n1 + b n2 + c n3 = -o with a, b, c > 0. For a right-angled
  // corner the coefficients are the offsets d_i, so this is d_i > 0: each
  // normal faces the LiDAR. For obtuse corners the thesis's coefficients can
  // change sign with the LiDAR's position (two LiDARs would disagree), while
  // "faces the LiDAR" holds for every LiDAR that sees the plane; we use it.
  for (Plane& plane : planes) {
    if (plane.offset < 0.0) plane = plane.flipped();
  }
  int bottom = 0;
  for (int i = 1; i < 3; ++i) {
    if (planes[i].normal.dot(up) > planes[bottom].normal.dot(up)) bottom = i;
  }
  std::array<int, 3> order{(bottom + 1) % 3, (bottom + 2) % 3, bottom};
  const Vec3& n1 = planes[order[0]].normal;
  const Vec3& n2 = planes[order[1]].normal;
  if (n2.cross(n1).dot(planes[bottom].normal) < 0.0) std::swap(order[0], order[1]);  // eq 2.5
  const std::array<Plane, 3> copy = planes;
  for (int i = 0; i < 3; ++i) planes[i] = copy[order[i]];
  return order;
}

std::array<double, 3> pairwise_angles_deg(const std::array<Plane, 3>& planes) {
  auto angle = [&](int i, int j) { return std::acos(std::clamp(planes[i].normal.dot(planes[j].normal), -1.0, 1.0)) / kDeg; };
  return {angle(0, 1), angle(0, 2), angle(1, 2)};
}

Corner find_corner(std::span<const Eigen::Vector3f> points, const std::vector<PlaneSegment>& segments, const PlanesConfig& config,
                   const std::string& source) {
  const int count = static_cast<int>(segments.size());
  Candidate best;
  bool found = false;
  for (int a = 0; a < count; ++a) {
    for (int b = a + 1; b < count; ++b) {
      for (int c = b + 1; c < count; ++c) {
        const std::array<Plane, 3> planes{segments[a].fit.plane, segments[b].fit.plane, segments[c].fit.plane};
        const double smallest = smallest_line_angle_deg(planes);
        if (smallest < config.min_any_angle_deg) continue;
        Candidate candidate{{a, b, c}, 0, smallest >= config.min_corner_angle_deg, true};
        const Vec3 o = corner_point(planes);
        for (const int s : candidate.segments) {
          candidate.support += segments[s].inliers.size();
          candidate.near_clouds = candidate.near_clouds && nearest_distance(points, segments[s].inliers, o) <= config.corner_max_gap;
        }
        if (!found || candidate.rank() > best.rank() || (candidate.rank() == best.rank() && candidate.support > best.support)) {
          best = candidate;
          found = true;
        }
      }
    }
  }
  if (!found) {
    throw InputError(source, "planes",
                     "found " + std::to_string(count) + " plane(s) but no three that meet at a corner (pairwise angles >= " +
                         std::to_string(config.min_any_angle_deg) + " deg); scan a corner of two walls and the floor, seen by both LiDARs");
  }
  Corner corner;
  for (int i = 0; i < 3; ++i) corner.planes[i] = segments[best.segments[i]].fit.plane;
  orient_and_order(corner.planes, config.up.normalized());
  corner.point = corner_point(corner.planes);
  corner.inliers = assign_points_impl(points, corner.planes, config.inlier_distance);
  corner.angles_ok = best.angles_ok;
  corner.near_clouds = best.near_clouds;
  return corner;
}

std::array<std::vector<std::uint32_t>, 3> assign_points(std::span<const Eigen::Vector3f> points, const std::array<Plane, 3>& planes,
                                                        double band) {
  return assign_points_impl(points, planes, band);
}

}  // namespace mlidar::calib
