#pragma once
// A wall corner in one cloud (thesis Sec. 2.3.1): the triple of extracted
// planes that forms a corner, its intersection point (eq 2.3), normal signs
// (eq 2.4) and left/right/bottom order (eq 2.5).
#include <array>
#include <span>
#include <string>
#include <vector>

#include "mlidar/calib/planes_types.hpp"
#include "mlidar/geometry/plane_ransac.hpp"

namespace mlidar::calib {

struct Corner {
  std::array<Plane, 3> planes;                        ///< oriented (eq 2.4) and ordered left, right, bottom (eq 2.5)
  std::array<std::vector<std::uint32_t>, 3> inliers;  ///< each point to its nearest plane of the three
  Vec3 point = Vec3::Zero();                          ///< eq 2.3
  bool angles_ok = true;                              ///< all pairwise angles in the corner range
  bool near_clouds = true;                            ///< corner within corner_max_gap of every plane's points
};

/// Intersection of three planes, N o = -d (eq 2.3). Precondition: normals independent.
Vec3 corner_point(const std::array<Plane, 3>& planes);

/// Flips normals to face the LiDAR (eq 2.4, see the .cpp for the variant), then
/// orders the planes: bottom = normal closest to `up`, left/right by
/// (n2 x n1) . n3 > 0 (eq 2.5). Returns the permutation applied (new i <- old perm[i]).
std::array<int, 3> orient_and_order(std::array<Plane, 3>& planes, const Vec3& up);

/// Chooses among `segments` the triple that forms a corner and has the most
/// inliers (pairwise angles in range, corner near the points; relaxed with
/// flags cleared when no triple passes). Throws InputError(source, "planes", ...)
/// when no three planes meet at a point (fewer than three, or near parallel).
Corner find_corner(std::span<const Eigen::Vector3f> points, const std::vector<PlaneSegment>& segments, const PlanesConfig& config,
                   const std::string& source);

/// Each finite point within `band` of a plane goes to its nearest plane of the three.
std::array<std::vector<std::uint32_t>, 3> assign_points(std::span<const Eigen::Vector3f> points, const std::array<Plane, 3>& planes,
                                                        double band);

/// Pairwise angles (deg) between the planes' normals: (1,2), (1,3), (2,3).
std::array<double, 3> pairwise_angles_deg(const std::array<Plane, 3>& planes);

}  // namespace mlidar::calib
