#include "mlidar/sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"

namespace mlidar::sim {
namespace {

/// Figure-eight x = a sin(w t), y = b sin(2 w t), heading along the velocity.
struct FigureEight {
  double a, b, w;
  Vec3 position(double t, double z) const { return {a * std::sin(w * t), b * std::sin(2 * w * t), z}; }
  double heading(double t) const { return std::atan2(2 * b * w * std::cos(2 * w * t), a * w * std::cos(w * t)); }
};

constexpr FigureEight kWalk{8.0, 3.0, 0.12};
constexpr FigureEight kDrive{45.0, 18.0, 0.13};

SE3 handheld_pose(double t, double height) {
  const double bob = 0.04 * std::sin(2.0 * std::numbers::pi * 1.8 * t);
  const double yaw = kWalk.heading(t) + 0.25 * std::sin(1.3 * t + 0.4);
  const double pitch = 0.15 * std::sin(0.9 * t + 1.1);
  const double roll = 0.2 * std::sin(1.1 * t + 2.0);
  return SE3(quat_from_rpy(Vec3(roll, pitch, yaw)), kWalk.position(t, height + bob));
}

/// Cumulative cubic B-spline basis (Kim et al. 1995): weights of the 3 differences.
Eigen::Vector3d cumulative_basis(double u) {
  const double u2 = u * u;
  const double u3 = u2 * u;
  return {(5.0 + 3.0 * u - 3.0 * u2 + u3) / 6.0, (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) / 6.0, u3 / 6.0};
}

}  // namespace

std::vector<std::string> trajectory_names() { return {"handheld", "vehicle", "corridor", "static"}; }

SimTrajectory SimTrajectory::named(const std::string& name, double base_height) {
  SimTrajectory trajectory;
  trajectory.height_ = base_height;
  trajectory.end_ = std::numeric_limits<double>::infinity();
  if (name == "handheld") {
    trajectory.kind_ = TrajectoryKind::kHandheld;
  } else if (name == "vehicle") {
    trajectory.kind_ = TrajectoryKind::kVehicle;
  } else if (name == "corridor") {
    trajectory.kind_ = TrajectoryKind::kCorridor;
  } else if (name == "static") {
    trajectory.fixed_ = SE3(Quat::Identity(), Vec3(0.0, 0.0, base_height));
  } else {
    throw UsageError("unknown trajectory '" + name + "' (known: handheld, vehicle, corridor, static, or a TUM file)");
  }
  return trajectory;
}

SimTrajectory SimTrajectory::stationary(const SE3& T_world_base) {
  SimTrajectory trajectory;
  trajectory.fixed_ = T_world_base;
  trajectory.end_ = std::numeric_limits<double>::infinity();
  return trajectory;
}

SimTrajectory SimTrajectory::through(const Trajectory& poses, double control_period) {
  if (poses.size() < 2) throw UsageError("a trajectory needs at least 2 poses to interpolate");
  SimTrajectory trajectory;
  trajectory.kind_ = TrajectoryKind::kSpline;
  trajectory.control_period_ = control_period;
  trajectory.start_ = poses.poses.front().stamp;
  trajectory.end_ = poses.poses.back().stamp;
  // Control poses every control_period by geodesic interpolation (lerp + slerp),
  // with the end poses repeated once on each side so the spline spans [start, end].
  const auto count = static_cast<std::size_t>(std::floor((trajectory.end_ - trajectory.start_) / control_period)) + 1;
  std::size_t segment = 0;
  auto sample = [&](double t) {
    while (segment + 2 < poses.size() && poses.poses[segment + 1].stamp < t) ++segment;
    const auto& a = poses.poses[segment];
    const auto& b = poses.poses[segment + 1];
    const double s = std::clamp((t - a.stamp) / (b.stamp - a.stamp), 0.0, 1.0);
    trajectory.control_positions_.push_back((1 - s) * a.T_world_base.translation() + s * b.T_world_base.translation());
    trajectory.control_rotations_.push_back(a.T_world_base.rotation().slerp(s, b.T_world_base.rotation()));
  };
  sample(trajectory.start_);
  for (std::size_t k = 0; k < count; ++k) sample(trajectory.start_ + static_cast<double>(k) * control_period);
  sample(trajectory.start_ + static_cast<double>(count - 1) * control_period);
  sample(trajectory.start_ + static_cast<double>(count - 1) * control_period);
  trajectory.end_ = trajectory.start_ + static_cast<double>(count - 1) * control_period;
  return trajectory;
}

SE3 SimTrajectory::spline_pose(double t) const {
  // Segment i spans control indices i..i+3 (index 0 is the repeated start).
  const double x = std::clamp((t - start_) / control_period_, 0.0, static_cast<double>(control_positions_.size() - 3));
  const auto i = std::min(static_cast<std::size_t>(x), control_positions_.size() - 4);
  const Eigen::Vector3d basis = cumulative_basis(x - static_cast<double>(i));
  Vec3 position = control_positions_[i];
  Quat rotation = control_rotations_[i];
  for (int j = 1; j <= 3; ++j) {
    const std::size_t k = i + static_cast<std::size_t>(j);
    position += basis[j - 1] * (control_positions_[k] - control_positions_[k - 1]);
    rotation = rotation * so3_exp(basis[j - 1] * so3_log(control_rotations_[k - 1].conjugate() * control_rotations_[k]));
  }
  return SE3(rotation.normalized(), position);
}

SE3 SimTrajectory::T_world_base(double t) const {
  switch (kind_) {
    case TrajectoryKind::kStatic:
      return fixed_;
    case TrajectoryKind::kHandheld:
      return handheld_pose(t, height_);
    case TrajectoryKind::kVehicle:
      return SE3(quat_from_rpy(Vec3(0.0, 0.0, kDrive.heading(t))), kDrive.position(t, height_));
    case TrajectoryKind::kCorridor:
      return SE3(Quat::Identity(), Vec3(1.5 * t, 0.0, height_));
    case TrajectoryKind::kSpline:
      return spline_pose(t);
  }
  return fixed_;
}

}  // namespace mlidar::sim
