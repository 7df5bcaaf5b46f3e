#pragma once
// Analytic scene primitives and their exact ray intersections (world frame,
// metres). A ray is o + t d with unit d; a hit is the smallest t in
// (t_min, t_max]. Rays starting inside a solid hit its inner surface.
#include <cstdint>
#include <optional>

#include "mlidar/core/se3.hpp"

namespace mlidar::sim {

enum class PrimitiveKind : std::uint8_t {
  kRectangle,  ///< bounded plane: centre, axes.col(0/1) in-plane, half_extent.x/y
  kBox,        ///< oriented box: centre, axes (world_R_box), half_extent
  kCylinder,   ///< vertical capped cylinder: centre, radius, half_extent.z = half height
  kSphere,     ///< centre, radius
  kGround,     ///< unbounded plane z = centre.z + slope.x (x - centre.x) + slope.y (y - centre.y)
};

struct Primitive {
  PrimitiveKind kind = PrimitiveKind::kBox;
  Vec3 centre = Vec3::Zero();
  Mat3 axes = Mat3::Identity();
  Vec3 half_extent = Vec3::Zero();
  double radius = 0.0;
  Eigen::Vector2d slope = Eigen::Vector2d::Zero();
  Vec3 velocity = Vec3::Zero();  ///< world m/s; centre is the position at time 0
  double reflectivity = 0.5;     ///< Lambertian albedo in [0, 1]
  int object_id = -1;            ///< labelled object this surface belongs to, or -1

  /// This primitive moved to time t (centre + velocity t).
  Primitive at_time(double t) const;
};

struct Ray {
  Vec3 origin;
  Vec3 direction;  ///< unit length
};

struct Hit {
  double t = 0.0;
  Vec3 normal = Vec3::UnitZ();  ///< unit, facing the ray origin
  double reflectivity = 0.0;
  int object_id = -1;
};

/// Exact intersection of ray and primitive, the nearest t in (t_min, t_max].
std::optional<Hit> intersect(const Primitive& primitive, const Ray& ray, double t_min, double t_max);

/// Axis-aligned bounds (min, max); unbounded primitives (ground) give infinities.
struct Bounds {
  Vec3 min;
  Vec3 max;
};
Bounds bounds(const Primitive& primitive);
bool is_bounded(const Primitive& primitive);

/// Factories (yaw in rad about world z).
Primitive make_rectangle(const Vec3& centre, const Mat3& axes, double half_u, double half_v, double reflectivity);
Primitive make_box(const Vec3& centre, double yaw, const Vec3& half_extent, double reflectivity, int object_id = -1);
Primitive make_cylinder(const Vec3& centre, double radius, double half_height, double reflectivity);
Primitive make_sphere(const Vec3& centre, double radius, double reflectivity);
Primitive make_ground(double height, const Eigen::Vector2d& slope, double reflectivity);

}  // namespace mlidar::sim
