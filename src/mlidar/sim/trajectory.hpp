#pragma once
// Smooth rig trajectories T_world_base(t), C2 in position and orientation.
//   static    : a fixed pose (tests)
//   handheld  : walking ~0.7..1.2 m/s on a figure-eight, x = 8 sin(w t),
//               y = 3 sin(2 w t), w = 0.12 rad/s, 1.8 Hz 4 cm step bob;
//               yaw follows the path plus sway, pitch and roll oscillate
//               (0.15..0.25 rad): excitation about all three axes
//   vehicle   : planar figure-eight drive x = 45 sin(w t), y = 18 sin(2 w t),
//               w = 0.13 rad/s: 3.7..7.5 m/s (slower in the turns); yaw along the path,
//               roll = pitch = 0, z constant (degenerate like the thesis's RV)
//   corridor  : straight along +x at 1.5 m/s, constant orientation
//   spline    : through given poses (a TUM file), a cubic B-spline in
//               position and a cumulative cubic B-spline on SO(3)
//               (Kim et al. 1995; Lovegrove et al., "Spline Fusion", BMVC 2013)
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::sim {

enum class TrajectoryKind : std::uint8_t { kStatic, kHandheld, kVehicle, kCorridor, kSpline };

class SimTrajectory {
 public:
  /// "handheld", "vehicle", "corridor" or "static" at base_height above the ground; UsageError otherwise.
  static SimTrajectory named(const std::string& name, double base_height);
  static SimTrajectory stationary(const SE3& T_world_base);
  /// B-spline with control poses resampled every control_period seconds from
  /// `poses` (at least 2, increasing stamps); the spline spans their time range.
  static SimTrajectory through(const Trajectory& poses, double control_period = 0.1);

  SE3 T_world_base(double t) const;
  double start_time() const { return start_; }
  double end_time() const { return end_; }  ///< +inf for analytic trajectories
  TrajectoryKind kind() const { return kind_; }

 private:
  TrajectoryKind kind_ = TrajectoryKind::kStatic;
  double height_ = 0.0;
  double start_ = 0.0;
  double end_ = 0.0;
  SE3 fixed_;
  std::vector<Vec3> control_positions_;
  std::vector<Quat> control_rotations_;
  double control_period_ = 0.1;

  SE3 spline_pose(double t) const;
};

std::vector<std::string> trajectory_names();

}  // namespace mlidar::sim
