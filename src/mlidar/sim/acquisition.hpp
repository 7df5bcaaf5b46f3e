#pragma once
// Spinning acquisition: one sweep of one LiDAR with motion distortion.
// Column c of C fires at t_c = sweep_offset + c * sweep_period / C after the
// frame stamp, all rings of a column at once, at azimuth -360 deg * c / C
// (clockwise seen from above, starting along the LiDAR's +x). The rig pose
// is evaluated at each column's time, so a moving rig distorts the sweep
// exactly as a real spinning sensor does. Points are stored in the LiDAR
// frame at their own firing time, column by column, rings ascending.
//   range     = exact hit distance + N(0, range_noise_sigma), kept when the
//               exact distance lies in [min_range, max_range]
//   dropout   = each return is lost with probability dropout_probability
//   intensity = 255 * reflectivity * |cos(incidence)|  (Lambertian)
#include <cstdint>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/sim/rig.hpp"
#include "mlidar/sim/scene.hpp"
#include "mlidar/sim/trajectory.hpp"

namespace mlidar::sim {

struct SimulatedScan {
  Scan scan;                   ///< stamp = frame stamp; time = seconds from it
  std::vector<int> object_id;  ///< per point: labelled object hit, or -1
  /// The exact (noise-free) hits on unlabelled scenery, world frame, with the surface's unit normal there.
  std::vector<Vec3> scenery_hits;
  std::vector<Vec3> scenery_normals;
};

/// Simulates the sweep of `lidar` for the frame stamped `frame_stamp`.
/// The noise and dropout draws come from std::mt19937_64(seed).
SimulatedScan simulate_sweep(const Scene& scene, const SimLidar& lidar, const SimTrajectory& trajectory, double frame_stamp,
                             std::uint64_t seed);

/// An independent seed per (run seed, frame, LiDAR) (SplitMix64 mixing), so
/// the output does not depend on the order or thread in which sweeps run.
std::uint64_t sweep_seed(std::uint64_t seed, std::uint64_t frame, std::uint64_t lidar);

}  // namespace mlidar::sim
