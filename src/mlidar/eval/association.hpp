#pragma once
// Checks on trajectories and pairing of ground-truth and estimated poses.
// Association follows evo's definition (evo/core/sync.py, associate_trajectories):
// every pose of the shorter trajectory is paired with the pose of the other
// whose stamp is nearest, kept when |dt| <= max_dt. mlidar additionally keeps
// pairs one-to-one: if two poses pick the same partner, the closer pair wins.
#include <cstddef>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::eval {

/// Index pairs (gt, est) into the two trajectories, increasing in both.
struct Association {
  std::vector<std::size_t> gt;
  std::vector<std::size_t> est;
  std::size_t size() const { return gt.size(); }
};

/// Throws InputError(source, ...) when the trajectory has fewer than 2 poses,
/// a non-finite stamp, translation or rotation, a quaternion that is not unit
/// length (|norm - 1| > 1e-3), or stamps that are not strictly increasing.
void validate_trajectory(const Trajectory& trajectory, const std::string& source);

/// Nearest-stamp association within max_dt seconds (both trajectories valid).
/// Throws InputError(est_source, "timestamp", ...) when fewer than 2 pairs are found.
Association associate_by_time(const Trajectory& gt, const Trajectory& est, double max_dt, const std::string& est_source);

/// Pairs pose i with pose i (KITTI files carry no stamps). Throws InputError
/// naming est_source when the pose counts differ.
Association associate_by_index(const Trajectory& gt, const Trajectory& est, const std::string& est_source);

}  // namespace mlidar::eval
