#include "mlidar/slam/deskew.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace mlidar::slam {

BodyVelocity BodyVelocity::from_relative_pose(const SE3& T_prev_curr, double dt) {
  if (!(dt > 0.0)) throw std::invalid_argument("BodyVelocity::from_relative_pose: dt must be > 0");
  BodyVelocity velocity;
  velocity.linear = T_prev_curr.translation() / dt;
  velocity.angular = so3_log(T_prev_curr.rotation()) / dt;
  return velocity;
}

SE3 BodyVelocity::pose_at(double tau) const { return {so3_exp(tau * angular), tau * linear}; }

void deskew_to_base(std::span<const Eigen::Vector3f> points, std::span<const float> times, std::span<const std::uint32_t> indices,
                    const SE3& T_base_lidar, const BodyVelocity& velocity, std::span<Eigen::Vector3f> out) {
  const std::size_t count = indices.empty() ? points.size() : indices.size();
  if (out.size() != count) throw std::invalid_argument("deskew_to_base: out size differs from the selection");
  if (!times.empty() && times.size() != points.size()) throw std::invalid_argument("deskew_to_base: times size differs from points");
  const Mat3 R_base_lidar = T_base_lidar.rotation_matrix();
  const Vec3& t_base_lidar = T_base_lidar.translation();
  const double speed = velocity.angular.norm();
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i = indices.empty() ? k : indices[k];
    if (i >= points.size()) throw std::invalid_argument("deskew_to_base: index out of range");
    const Vec3 p_base = R_base_lidar * points[i].cast<double>() + t_base_lidar;
    if (times.empty()) {
      out[k] = p_base.cast<float>();
      continue;
    }
    const double tau = times[i];
    // Exp(tau w) p by Rodrigues' formula on the unit axis (eq 4.12).
    Vec3 rotated = p_base;
    if (speed * std::abs(tau) > 1e-12) {
      const Vec3 axis = velocity.angular / speed;
      const double angle = speed * tau;
      const double c = std::cos(angle);
      rotated = c * p_base + std::sin(angle) * axis.cross(p_base) + (1.0 - c) * axis.dot(p_base) * axis;
    }
    out[k] = (rotated + tau * velocity.linear).cast<float>();
  }
}

namespace {

/// Exp(angle * axis) p for a unit axis (Rodrigues). Within a sweep the angle is
/// small, so sin and cos come from their Taylor series below 0.25 rad (terms to
/// angle^7 / angle^8: error < 1e-9, far below the points' float precision).
Vec3 rotate_about(const Vec3& axis, double angle, const Vec3& p) {
  double s = 0.0, c = 1.0;
  if (std::abs(angle) < 0.25) {
    const double a2 = angle * angle;
    s = angle * (1.0 - a2 / 6.0 * (1.0 - a2 / 20.0 * (1.0 - a2 / 42.0)));
    c = 1.0 - a2 / 2.0 * (1.0 - a2 / 12.0 * (1.0 - a2 / 30.0 * (1.0 - a2 / 56.0)));
  } else {
    s = std::sin(angle);
    c = std::cos(angle);
  }
  return c * p + s * axis.cross(p) + (1.0 - c) * axis.dot(p) * axis;
}

/// Unit axis and rate of an angular velocity (axis x, rate 0 when it is zero).
std::pair<Vec3, double> axis_rate(const Vec3& angular) {
  const double rate = angular.norm();
  return rate > 1e-12 ? std::pair{Vec3(angular / rate), rate} : std::pair{Vec3(Vec3::UnitX()), 0.0};
}

}  // namespace

void redeskew(std::span<const float> times, const BodyVelocity& used, const BodyVelocity& refined, std::span<Eigen::Vector3f> points) {
  if (times.empty()) return;
  if (times.size() != points.size()) throw std::invalid_argument("redeskew: times size differs from points");
  const auto [used_axis, used_rate] = axis_rate(used.angular);
  const auto [refined_axis, refined_rate] = axis_rate(refined.angular);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double tau = times[i];
    const Vec3 p_base = rotate_about(used_axis, -tau * used_rate, points[i].cast<double>() - tau * used.linear);
    points[i] = (rotate_about(refined_axis, tau * refined_rate, p_base) + tau * refined.linear).cast<float>();
  }
}

}  // namespace mlidar::slam
