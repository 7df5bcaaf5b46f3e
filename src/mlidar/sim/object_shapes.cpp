#include "mlidar/sim/object_shapes.hpp"

#include <cmath>

#include "mlidar/sim/scene_layout.hpp"

namespace mlidar::sim {
namespace {

using layout::uniform;

/// One part in the object's frame: an upright box (half extents), a vertical cylinder (radius, half height in
/// half.z) or a sphere (radius).
struct Part {
  PrimitiveKind kind;
  Vec3 centre;
  Vec3 half;
  double radius;
  double reflectivity;
};

Part box_part(const Vec3& centre, const Vec3& half, double reflectivity) { return {PrimitiveKind::kBox, centre, half, 0.0, reflectivity}; }
Part cylinder_part(const Vec3& centre, double radius, double half_height, double reflectivity) {
  return {PrimitiveKind::kCylinder, centre, Vec3(radius, radius, half_height), radius, reflectivity};
}
Part sphere_part(const Vec3& centre, double radius, double reflectivity) {
  return {PrimitiveKind::kSphere, centre, Vec3::Constant(radius), radius, reflectivity};
}

std::vector<Part> car_parts(std::mt19937_64& rng) {
  const double length = uniform(rng, 3.6, 5.2);
  const double width = uniform(rng, 1.6, 2.0);
  const double height = uniform(rng, 1.4, 1.9);
  const double wheel_radius = uniform(rng, 0.28, 0.36);
  const double body_top = height * uniform(rng, 0.52, 0.62);
  const double body_bottom = 0.3;
  const double cabin_length = length * uniform(rng, 0.45, 0.6);
  const double cabin_shift = length * uniform(rng, -0.12, 0.02);
  const double axle = length / 2 - uniform(rng, 0.75, 1.0);
  const double paint = uniform(rng, 0.2, 0.9);
  std::vector<Part> parts{
      box_part(Vec3(0, 0, (body_top + body_bottom) / 2), Vec3(length / 2, width / 2, (body_top - body_bottom) / 2), paint),
      box_part(Vec3(cabin_shift, 0, (height + body_top) / 2), Vec3(cabin_length / 2, 0.46 * width, (height - body_top) / 2), 0.2)};
  for (const double x : {axle, -axle}) {
    for (const double y : {width / 2 - 0.12, 0.12 - width / 2})
      parts.push_back(box_part(Vec3(x, y, wheel_radius), Vec3(wheel_radius, 0.11, wheel_radius), 0.1));
  }
  return parts;
}

std::vector<Part> pedestrian_parts(std::mt19937_64& rng) {
  const double height = uniform(rng, 1.5, 1.95);
  const double shoulder = uniform(rng, 0.36, 0.46);
  const double depth = uniform(rng, 0.2, 0.28);
  const double stride = uniform(rng, -0.3, 0.3);
  const double leg_radius = uniform(rng, 0.065, 0.08);
  const double head_radius = uniform(rng, 0.1, 0.12);
  const double clothes = uniform(rng, 0.15, 0.7);
  const double hip = 0.47 * height, neck = 0.82 * height;
  std::vector<Part> parts;
  for (const double side : {1.0, -1.0}) {
    parts.push_back(cylinder_part(Vec3(side * stride / 2, side * 0.1, hip / 2), leg_radius, hip / 2, clothes));
    parts.push_back(cylinder_part(Vec3(-side * stride / 3, side * (shoulder / 2 + 0.05), (0.45 * height + neck) / 2), 0.045,
                                  (neck - 0.45 * height) / 2, clothes));
  }
  parts.push_back(box_part(Vec3(0, 0, (hip + neck) / 2), Vec3(depth / 2, shoulder / 2, (neck - hip) / 2), clothes));
  parts.push_back(sphere_part(Vec3(0.02, 0, height - head_radius), head_radius, 0.4));
  return parts;
}

std::vector<Part> cyclist_parts(std::mt19937_64& rng) {
  const double wheel_radius = uniform(rng, 0.31, 0.36);
  const double wheelbase = uniform(rng, 0.95, 1.15);
  const double seat = wheel_radius + uniform(rng, 0.45, 0.58);
  const double torso_half = uniform(rng, 0.25, 0.3);
  const double head_radius = uniform(rng, 0.1, 0.12);
  const double clothes = uniform(rng, 0.15, 0.7);
  std::vector<Part> parts;
  for (const double x : {wheelbase / 2, -wheelbase / 2})
    parts.push_back(box_part(Vec3(x, 0, wheel_radius), Vec3(wheel_radius, 0.02, wheel_radius), 0.3));
  parts.push_back(box_part(Vec3(0, 0, wheel_radius + 0.15), Vec3(0.4 * wheelbase, 0.02, 0.04), 0.6));
  parts.push_back(box_part(Vec3(-0.2, 0, (wheel_radius + seat) / 2), Vec3(0.03, 0.02, (seat - wheel_radius) / 2), 0.6));
  parts.push_back(box_part(Vec3(wheelbase / 2 - 0.1, 0, seat + 0.1), Vec3(0.03, 0.25, 0.02), 0.6));
  for (const double y : {0.12, -0.12})
    parts.push_back(cylinder_part(Vec3(-0.1, y, (0.6 * wheel_radius + seat) / 2), 0.07, (seat - 0.6 * wheel_radius) / 2, clothes));
  parts.push_back(box_part(Vec3(0.05, 0, seat + torso_half), Vec3(0.14, 0.2, torso_half), clothes));
  parts.push_back(sphere_part(Vec3(0.12, 0, seat + 2 * torso_half + head_radius), head_radius, 0.4));
  return parts;
}

Primitive to_world(const Part& part, const Vec3& origin, double yaw, int id) {
  const Vec3 centre = origin + Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * part.centre;
  Primitive primitive;
  switch (part.kind) {
    case PrimitiveKind::kBox:
      primitive = make_box(centre, yaw, part.half, part.reflectivity);
      break;
    case PrimitiveKind::kCylinder:
      primitive = make_cylinder(centre, part.radius, part.half.z(), part.reflectivity);
      break;
    default:
      primitive = make_sphere(centre, part.radius, part.reflectivity);
      break;
  }
  primitive.object_id = id;
  return primitive;
}

}  // namespace

std::string kitti_class_name(ObjectClass object_class) {
  switch (object_class) {
    case ObjectClass::kCar:
      return "Car";
    case ObjectClass::kPedestrian:
      return "Pedestrian";
    case ObjectClass::kCyclist:
      return "Cyclist";
  }
  return "Car";
}

ShapedObject make_shaped_object(ObjectClass object_class, const Vec3& origin, double yaw, int id, std::mt19937_64& rng) {
  const std::vector<Part> parts = object_class == ObjectClass::kCar          ? car_parts(rng)
                                  : object_class == ObjectClass::kPedestrian ? pedestrian_parts(rng)
                                                                             : cyclist_parts(rng);
  // The tight upright box in the object's frame; the ground is its floor.
  Vec3 low = Vec3::Constant(1e9), high = Vec3::Constant(-1e9);
  for (const auto& part : parts) {
    low = low.cwiseMin(part.centre - part.half);
    high = high.cwiseMax(part.centre + part.half);
  }
  low.z() = 0.0;
  ShapedObject object;
  object.label.id = id;
  object.label.type = kitti_class_name(object_class);
  object.label.size = high - low;
  object.label.centre = origin + Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * ((low + high) / 2);
  object.label.yaw = yaw;
  for (const auto& part : parts) object.parts.push_back(to_world(part, origin, yaw, id));
  return object;
}

}  // namespace mlidar::sim
