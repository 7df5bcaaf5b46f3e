#pragma once
// Exact overlap of two upright boxes that may be rotated about z (io::Box3D, bottom centre, l w h, yaw):
//   BEV  IoU = A(P_a ∩ P_b) / (A(P_a) + A(P_b) - A(P_a ∩ P_b))             P = the box's footprint rectangle
//   3D   IoU = A(P_a ∩ P_b) · dz / (V_a + V_b - A(P_a ∩ P_b) · dz)          dz = overlap of [z, z + h] of both
// The footprints' intersection is a convex polygon: one rectangle clipped by the four edges of the other
// (Sutherland-Hodgman), its area by the shoelace formula. A vertex on an edge counts as inside, so touching,
// identical, nested and parallel-edged boxes need no special case (a touching pair has area 0).
#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/io/detection_labels.hpp"

namespace mlidar::eval {

using Vec2 = Eigen::Vector2d;

/// The footprint's corners, counter-clockwise seen from above (+z).
std::array<Vec2, 4> footprint_corners(const io::Box3D& box);

/// Area of a simple polygon (shoelace formula); positive for counter-clockwise vertices.
double signed_polygon_area(std::span<const Vec2> polygon);

/// `subject` clipped to the convex counter-clockwise polygon `clip` (Sutherland-Hodgman); may hold repeated
/// vertices, empty when nothing is left.
std::vector<Vec2> clip_to_convex(std::span<const Vec2> subject, std::span<const Vec2> clip);

/// Area (m²) of the intersection of both footprints.
double footprint_intersection_area(const io::Box3D& a, const io::Box3D& b);

/// BEV IoU in [0, 1].
double bev_iou(const io::Box3D& a, const io::Box3D& b);
/// 3D IoU in [0, 1].
double iou_3d(const io::Box3D& a, const io::Box3D& b);

}  // namespace mlidar::eval
