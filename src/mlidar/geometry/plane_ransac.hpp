#pragma once
// Sequential RANSAC for several planes (thesis Sec. 2.3.1): find the plane
// with most inliers (3-point hypotheses, eq 2.1 distance), refine it by a
// least-squares fit on its inliers (eq 2.2) and re-collect them, remove them,
// repeat. Seeded: the same points and seed give the same planes.
#include <cstdint>
#include <span>
#include <vector>

#include "mlidar/geometry/plane_fit.hpp"

namespace mlidar {

struct PlaneRansacConfig {
  double inlier_distance = 0.2;   ///< m, |n.p + d| below this is an inlier
  int max_iterations = 1000;      ///< hypotheses per plane at most (fewer once 99.9 % confident)
  std::size_t min_inliers = 100;  ///< stop when the best plane has fewer
  int max_planes = 6;             ///< planes to extract at most
  int refine_passes = 3;          ///< fit-then-recollect passes after the best hypothesis
  std::uint64_t seed = 1;
};

struct PlaneSegment {
  PlaneFit fit;
  std::vector<std::uint32_t> inliers;  ///< indices into the input points, ascending
};

/// Planes in extraction order (most supported first). Non-finite points are
/// ignored. Throws std::invalid_argument for a config out of range or 2^32
/// points or more.
std::vector<PlaneSegment> extract_planes(std::span<const Eigen::Vector3f> points, const PlaneRansacConfig& config);

}  // namespace mlidar
