#include "mlidar/sim/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mlidar::sim {
namespace {

constexpr double kParallel = 1e-12;

Hit make_hit(double t, const Vec3& outward_normal, const Ray& ray, const Primitive& primitive) {
  Hit hit;
  hit.t = t;
  hit.normal = outward_normal.dot(ray.direction) > 0.0 ? Vec3(-outward_normal) : outward_normal;
  hit.reflectivity = primitive.reflectivity;
  hit.object_id = primitive.object_id;
  return hit;
}

/// Plane n.(p - c) = 0 bounded by |u.(p-c)| <= a, |v.(p-c)| <= b.
std::optional<Hit> intersect_rectangle(const Primitive& rect, const Ray& ray, double t_min, double t_max) {
  const Vec3 normal = rect.axes.col(2);
  const double denom = normal.dot(ray.direction);
  if (std::abs(denom) < kParallel) return std::nullopt;
  const double t = normal.dot(rect.centre - ray.origin) / denom;
  if (!(t > t_min && t <= t_max)) return std::nullopt;
  const Vec3 local = rect.axes.transpose() * (ray.origin + t * ray.direction - rect.centre);
  if (std::abs(local.x()) > rect.half_extent.x() || std::abs(local.y()) > rect.half_extent.y()) return std::nullopt;
  return make_hit(t, normal, ray, rect);
}

/// Slab method (Kay & Kajiya 1986) in the box frame.
std::optional<Hit> intersect_box(const Primitive& box, const Ray& ray, double t_min, double t_max) {
  const Vec3 o = box.axes.transpose() * (ray.origin - box.centre);
  const Vec3 d = box.axes.transpose() * ray.direction;
  double t_enter = -std::numeric_limits<double>::infinity();
  double t_exit = std::numeric_limits<double>::infinity();
  int axis_enter = 0;
  int axis_exit = 0;
  for (int a = 0; a < 3; ++a) {
    const double h = box.half_extent[a];
    if (std::abs(d[a]) < kParallel) {
      if (std::abs(o[a]) > h) return std::nullopt;
      continue;
    }
    double t0 = (-h - o[a]) / d[a];
    double t1 = (h - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_enter) {
      t_enter = t0;
      axis_enter = a;
    }
    if (t1 < t_exit) {
      t_exit = t1;
      axis_exit = a;
    }
  }
  if (t_enter > t_exit) return std::nullopt;
  const bool from_outside = t_enter > t_min;
  const double t = from_outside ? t_enter : t_exit;
  if (!(t > t_min && t <= t_max)) return std::nullopt;
  const int axis = from_outside ? axis_enter : axis_exit;
  return make_hit(t, box.axes.col(axis), ray, box);
}

/// Quadratic a t^2 + 2 b t + c = 0: roots in ascending order.
bool solve_quadratic(double a, double b, double c, double& r0, double& r1) {
  const double disc = b * b - a * c;
  if (disc < 0.0 || a <= 0.0) return false;
  const double s = std::sqrt(disc);
  // Numerically stable form (Press et al., Numerical Recipes 5.6).
  const double q = b > 0.0 ? -(b + s) : -(b - s);
  r0 = q / a;
  r1 = q != 0.0 ? c / q : r0;
  if (r0 > r1) std::swap(r0, r1);
  return true;
}

std::optional<Hit> intersect_cylinder(const Primitive& cyl, const Ray& ray, double t_min, double t_max) {
  const Vec3 o = ray.origin - cyl.centre;
  const Vec3& d = ray.direction;
  const double h = cyl.half_extent.z();
  std::optional<Hit> best;
  auto consider = [&](double t, const Vec3& normal) {
    if (t > t_min && t <= t_max && (!best || t < best->t)) best = make_hit(t, normal, ray, cyl);
  };
  double r0 = 0.0;
  double r1 = 0.0;
  if (solve_quadratic(d.x() * d.x() + d.y() * d.y(), o.x() * d.x() + o.y() * d.y(), o.x() * o.x() + o.y() * o.y() - cyl.radius * cyl.radius,
                      r0, r1)) {
    for (const double t : {r0, r1}) {
      const Vec3 p = o + t * d;
      if (std::abs(p.z()) <= h) consider(t, Vec3(p.x(), p.y(), 0.0).normalized());
    }
  }
  if (std::abs(d.z()) > kParallel) {
    for (const double cap : {-h, h}) {
      const double t = (cap - o.z()) / d.z();
      const Vec3 p = o + t * d;
      if (p.x() * p.x() + p.y() * p.y() <= cyl.radius * cyl.radius) consider(t, Vec3(0.0, 0.0, cap > 0 ? 1.0 : -1.0));
    }
  }
  return best;
}

std::optional<Hit> intersect_sphere(const Primitive& sphere, const Ray& ray, double t_min, double t_max) {
  const Vec3 o = ray.origin - sphere.centre;
  double r0 = 0.0;
  double r1 = 0.0;
  if (!solve_quadratic(1.0, o.dot(ray.direction), o.squaredNorm() - sphere.radius * sphere.radius, r0, r1)) return std::nullopt;
  for (const double t : {r0, r1}) {
    if (t > t_min && t <= t_max) return make_hit(t, (o + t * ray.direction) / sphere.radius, ray, sphere);
  }
  return std::nullopt;
}

std::optional<Hit> intersect_ground(const Primitive& ground, const Ray& ray, double t_min, double t_max) {
  // z - sx x - sy y = k, normal (-sx, -sy, 1).
  const Vec3 normal = Vec3(-ground.slope.x(), -ground.slope.y(), 1.0).normalized();
  const double denom = normal.dot(ray.direction);
  if (std::abs(denom) < kParallel) return std::nullopt;
  const double t = normal.dot(ground.centre - ray.origin) / denom;
  if (!(t > t_min && t <= t_max)) return std::nullopt;
  return make_hit(t, normal, ray, ground);
}

}  // namespace

Primitive Primitive::at_time(double t) const {
  Primitive moved = *this;
  moved.centre += velocity * t;
  return moved;
}

std::optional<Hit> intersect(const Primitive& primitive, const Ray& ray, double t_min, double t_max) {
  switch (primitive.kind) {
    case PrimitiveKind::kRectangle:
      return intersect_rectangle(primitive, ray, t_min, t_max);
    case PrimitiveKind::kBox:
      return intersect_box(primitive, ray, t_min, t_max);
    case PrimitiveKind::kCylinder:
      return intersect_cylinder(primitive, ray, t_min, t_max);
    case PrimitiveKind::kSphere:
      return intersect_sphere(primitive, ray, t_min, t_max);
    case PrimitiveKind::kGround:
      return intersect_ground(primitive, ray, t_min, t_max);
  }
  return std::nullopt;
}

bool is_bounded(const Primitive& primitive) { return primitive.kind != PrimitiveKind::kGround; }

Bounds bounds(const Primitive& p) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  switch (p.kind) {
    case PrimitiveKind::kRectangle:
    case PrimitiveKind::kBox: {
      const Vec3 h(p.half_extent.x(), p.half_extent.y(), p.kind == PrimitiveKind::kBox ? p.half_extent.z() : 0.0);
      const Vec3 reach = p.axes.cwiseAbs() * h;  // half-size of the AABB of an oriented box
      return {p.centre - reach, p.centre + reach};
    }
    case PrimitiveKind::kCylinder: {
      const Vec3 reach(p.radius, p.radius, p.half_extent.z());
      return {p.centre - reach, p.centre + reach};
    }
    case PrimitiveKind::kSphere:
      return {p.centre.array() - p.radius, p.centre.array() + p.radius};
    case PrimitiveKind::kGround:
      break;
  }
  return {Vec3::Constant(-inf), Vec3::Constant(inf)};
}

Primitive make_rectangle(const Vec3& centre, const Mat3& axes, double half_u, double half_v, double reflectivity) {
  Primitive p;
  p.kind = PrimitiveKind::kRectangle;
  p.centre = centre;
  p.axes = axes;
  p.half_extent = Vec3(half_u, half_v, 0.0);
  p.reflectivity = reflectivity;
  return p;
}

Primitive make_box(const Vec3& centre, double yaw, const Vec3& half_extent, double reflectivity, int object_id) {
  Primitive p;
  p.kind = PrimitiveKind::kBox;
  p.centre = centre;
  p.axes = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  p.half_extent = half_extent;
  p.reflectivity = reflectivity;
  p.object_id = object_id;
  return p;
}

Primitive make_cylinder(const Vec3& centre, double radius, double half_height, double reflectivity) {
  Primitive p;
  p.kind = PrimitiveKind::kCylinder;
  p.centre = centre;
  p.radius = radius;
  p.half_extent = Vec3(0.0, 0.0, half_height);
  p.reflectivity = reflectivity;
  return p;
}

Primitive make_sphere(const Vec3& centre, double radius, double reflectivity) {
  Primitive p;
  p.kind = PrimitiveKind::kSphere;
  p.centre = centre;
  p.radius = radius;
  p.reflectivity = reflectivity;
  return p;
}

Primitive make_ground(double height, const Eigen::Vector2d& slope, double reflectivity) {
  Primitive p;
  p.kind = PrimitiveKind::kGround;
  p.centre = Vec3(0.0, 0.0, height);
  p.slope = slope;
  p.reflectivity = reflectivity;
  return p;
}

}  // namespace mlidar::sim
