#pragma once
// Pose lookup at an arbitrary time inside a Trajectory.
#include <optional>

#include "mlidar/core/types.hpp"

namespace mlidar {

/// T_world_base at `stamp`, interpolated on the SE(3) geodesic (constant body
/// twist) between the two stamped poses that bracket it.
///
/// Out of range is an ordinary answer, not an error: returns std::nullopt when
/// the trajectory is empty, `stamp` is NaN, or it lies outside
/// [first stamp, last stamp] (callers decide whether to skip or extrapolate).
/// A stamp equal to a stored one returns that pose exactly.
/// Precondition: stamps are non-decreasing (Trajectory's invariant). The search
/// is a bounds-checked bisection, so unordered stamps give a wrong pose but
/// never read out of bounds; at a duplicated stamp, one of the poses stored there.
/// Cost: O(log n).
std::optional<SE3> interpolate_pose(const Trajectory& trajectory, double stamp);

}  // namespace mlidar
