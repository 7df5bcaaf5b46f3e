#include "mlidar/sim/ground_truth.hpp"

#include <cmath>
#include <numbers>

namespace mlidar::sim {

io::KittiObject box_in_base(const LabelledObject& object, double t, const SE3& T_world_base) {
  const SE3 T_base_world = T_world_base.inverse();
  const Vec3 bottom_world = object.centre_at(t) - Vec3(0.0, 0.0, object.size.z() / 2);
  const Vec3 heading_base = T_base_world.rotation() * Vec3(std::cos(object.yaw), std::sin(object.yaw), 0.0);
  io::KittiObject box;
  box.type = object.type;
  box.location = T_base_world * bottom_world;
  box.dimensions = Vec3(object.size.z(), object.size.y(), object.size.x());
  box.rotation_y = std::atan2(heading_base.y(), heading_base.x());
  double alpha = box.rotation_y - std::atan2(box.location.y(), box.location.x());
  while (alpha > std::numbers::pi) alpha -= 2 * std::numbers::pi;
  while (alpha <= -std::numbers::pi) alpha += 2 * std::numbers::pi;
  box.alpha = alpha;
  return box;
}

bool box_contains(const io::KittiObject& box, const Vec3& p_base, double margin) {
  const Vec3 centre = box.location + Vec3(0.0, 0.0, box.dimensions.x() / 2);
  const Vec3 local = Eigen::AngleAxisd(-box.rotation_y, Vec3::UnitZ()) * (p_base - centre);
  const Vec3 half(box.dimensions.z() / 2, box.dimensions.y() / 2, box.dimensions.x() / 2);
  return (local.array().abs() <= half.array() + margin).all();
}

}  // namespace mlidar::sim
