#pragma once
// Do the LiDARs' points agree in the map? Each map point keeps the LiDAR that
// saw it (VoxelMap sources). For a sample of LiDAR j's points: the distance
// to the plane fitted to its 5 nearest points of LiDAR j itself (the point left
// out), and to the plane of its 5 nearest points of the other LiDARs, both
// within 1 m and only where those 5 are planar (smallest eigenvalue of their
// scatter below a tenth of the middle one) and spread 10 cm across (1-sigma
// along the second direction): 5 points of one scan line fit a plane through
// that line whatever its tilt, which made a LiDAR's own planes too good early in
// a run (room, 12-30 frames: 3.1-3.7 with right extrinsics; 1.6-1.8 with the spread). With right extrinsics the two
// medians are alike (the same surfaces, the same noise); with a wrong one the
// LiDAR's points sit off the others' surfaces by the error. Measured on the
// simulated rigs (docs/benchmarks.md "A given extrinsic that disagrees with the
// map"): right extrinsics 0.7-1.4, a 0.02 m error along each axis 3.1-6.1 at the
// first test, 0.25 deg about each 4.2-4.9, 0.1 m or 1 deg 7-13.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {

struct SourceConsistency {
  std::uint8_t source = VoxelMap::kNoSource;
  std::size_t self_planes = 0;   ///< sampled points with a planar neighbourhood of their own LiDAR
  std::size_t cross_planes = 0;  ///< ... of the other LiDARs
  double self_m = 0.0;           ///< median distance to their own LiDAR's planes
  double cross_m = 0.0;          ///< median distance to the other LiDARs' planes
};

/// The test's ratio for all[i]: its cross_m over the largest self_m of all sources (its own or another's), so that
/// a precise LiDAR's points are not judged against a noisier LiDAR's planes as if they were its own (0 when it has
/// no plane of either kind).
double consistency_ratio(const std::vector<SourceConsistency>& all, std::size_t i);

/// Per source in [0, sources) with points in `map`: up to `samples` of its points (evenly through them) judged as
/// above. Deterministic.
std::vector<SourceConsistency> map_consistency(const VoxelMap& map, std::size_t sources, std::size_t samples = 1000);

}  // namespace mlidar::slam
