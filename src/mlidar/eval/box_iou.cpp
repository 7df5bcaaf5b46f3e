// Rotated-box overlap (formulas in box_iou.hpp).
#include "mlidar/eval/box_iou.hpp"

#include <algorithm>
#include <cmath>

namespace mlidar::eval {
namespace {

/// z-component of the cross product (b - a) x (p - a): > 0 when p lies left of the directed edge a -> b.
double side_of(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

/// `polygon` clipped to the half-plane left of (or on) the directed line a -> b (one Sutherland-Hodgman pass).
std::vector<Vec2> clip_to_half_plane(const std::vector<Vec2>& polygon, const Vec2& a, const Vec2& b) {
  std::vector<Vec2> kept;
  kept.reserve(polygon.size() + 1);
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Vec2& current = polygon[i];
    const Vec2& next = polygon[(i + 1) % polygon.size()];
    const double s_current = side_of(a, b, current);
    const double s_next = side_of(a, b, next);
    if (s_current >= 0.0) kept.push_back(current);
    // The edge crosses the line strictly: the signs differ, so the denominator is never 0.
    if ((s_current >= 0.0) != (s_next >= 0.0)) kept.push_back(current + (s_current / (s_current - s_next)) * (next - current));
  }
  return kept;
}

/// Overlap of the vertical intervals [z, z + h] of both boxes (m), 0 when they are apart.
double vertical_overlap(const io::Box3D& a, const io::Box3D& b) {
  const double top = std::min(a.center_bottom.z() + a.height, b.center_bottom.z() + b.height);
  const double bottom = std::max(a.center_bottom.z(), b.center_bottom.z());
  return std::max(0.0, top - bottom);
}

/// True when the footprints' circumscribed circles are apart (a cheap test before clipping).
bool footprints_far_apart(const io::Box3D& a, const io::Box3D& b) {
  const double reach = 0.5 * (std::hypot(a.length, a.width) + std::hypot(b.length, b.width));
  return (a.center_bottom.head<2>() - b.center_bottom.head<2>()).squaredNorm() > reach * reach;
}

/// intersection / union, 0 for an empty union.
double ratio_of_union(double intersection, double size_a, double size_b) {
  const double union_size = size_a + size_b - intersection;
  return union_size > 0.0 ? std::clamp(intersection / union_size, 0.0, 1.0) : 0.0;
}

}  // namespace

std::array<Vec2, 4> footprint_corners(const io::Box3D& box) {
  const Vec2 centre = box.center_bottom.head<2>();
  const Vec2 along = 0.5 * box.length * Vec2(std::cos(box.yaw), std::sin(box.yaw));
  const Vec2 across = 0.5 * box.width * Vec2(-std::sin(box.yaw), std::cos(box.yaw));
  return {centre + along + across, centre - along + across, centre - along - across, centre + along - across};
}

double signed_polygon_area(std::span<const Vec2> polygon) {
  double twice_area = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Vec2& p = polygon[i];
    const Vec2& q = polygon[(i + 1) % polygon.size()];
    twice_area += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * twice_area;
}

std::vector<Vec2> clip_to_convex(std::span<const Vec2> subject, std::span<const Vec2> clip) {
  std::vector<Vec2> polygon(subject.begin(), subject.end());
  for (std::size_t i = 0; i < clip.size() && !polygon.empty(); ++i)
    polygon = clip_to_half_plane(polygon, clip[i], clip[(i + 1) % clip.size()]);
  return polygon;
}

double footprint_intersection_area(const io::Box3D& a, const io::Box3D& b) {
  if (footprints_far_apart(a, b)) return 0.0;
  const std::array<Vec2, 4> corners_a = footprint_corners(a);
  const std::array<Vec2, 4> corners_b = footprint_corners(b);
  const std::vector<Vec2> overlap = clip_to_convex(corners_a, corners_b);
  return overlap.size() < 3 ? 0.0 : std::max(0.0, signed_polygon_area(overlap));
}

double bev_iou(const io::Box3D& a, const io::Box3D& b) {
  return ratio_of_union(footprint_intersection_area(a, b), a.length * a.width, b.length * b.width);
}

double iou_3d(const io::Box3D& a, const io::Box3D& b) {
  const double dz = vertical_overlap(a, b);
  if (dz <= 0.0) return 0.0;
  const double intersection = footprint_intersection_area(a, b) * dz;
  return ratio_of_union(intersection, a.length * a.width * a.height, b.length * b.width * b.height);
}

}  // namespace mlidar::eval
