#include "mlidar/core/trajectory_interpolation.hpp"

#include <cstddef>

namespace mlidar {

std::optional<SE3> interpolate_pose(const Trajectory& trajectory, double stamp) {
  const auto& poses = trajectory.poses;
  if (poses.empty()) return std::nullopt;
  // Written so that NaN fails the test.
  if (!(stamp >= poses.front().stamp && stamp <= poses.back().stamp)) return std::nullopt;

  // Bisection keeps the invariant poses[lo].stamp <= stamp, and stamp < poses[hi].stamp
  // unless hi is the last index.
  std::size_t lo = 0;
  std::size_t hi = poses.size() - 1;
  while (hi - lo > 1) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (poses[mid].stamp <= stamp) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const StampedPose& before = poses[lo];
  if (stamp == before.stamp) return before.T_world_base;
  const StampedPose& after = poses[hi];
  if (stamp == after.stamp) return after.T_world_base;
  const double span = after.stamp - before.stamp;
  if (!(span > 0.0)) return before.T_world_base;  // duplicated or unordered stamps
  return interpolate(before.T_world_base, after.T_world_base, (stamp - before.stamp) / span);
}

}  // namespace mlidar
