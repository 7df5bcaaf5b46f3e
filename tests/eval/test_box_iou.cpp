// Rotated-box IoU against hand-computed values and a Monte-Carlo volume estimate.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/eval/box_iou.hpp"

namespace mlidar::eval {
namespace {

using io::Box3D;

Box3D box(Vec3 centre, double l, double w, double h, double yaw) { return {centre, l, w, h, yaw}; }

TEST(BoxIou, IdenticalBoxesGiveOne) {
  for (const double yaw : {0.0, 0.3, std::numbers::pi / 2, -2.5}) {
    const Box3D a = box({10.0, -4.0, -1.6}, 4.4, 1.8, 1.5, yaw);
    EXPECT_NEAR(iou_3d(a, a), 1.0, 1e-12) << yaw;
    EXPECT_NEAR(bev_iou(a, a), 1.0, 1e-12) << yaw;
  }
}

TEST(BoxIou, HalfLengthShiftAlongTheHeadingGivesOneThird) {
  // Shifted by l/2 along its own length: the overlap is half a box, the union 1.5 boxes: IoU = 0.5 / 1.5 = 1/3.
  for (const double yaw : {0.0, 0.7, -1.9}) {
    const Box3D a = box({3.0, 1.0, 0.2}, 4.0, 2.0, 1.5, yaw);
    Box3D b = a;
    b.center_bottom += 2.0 * Vec3(std::cos(yaw), std::sin(yaw), 0.0);
    EXPECT_NEAR(iou_3d(a, b), 1.0 / 3.0, 1e-12) << yaw;
    EXPECT_NEAR(bev_iou(a, b), 1.0 / 3.0, 1e-12) << yaw;
    EXPECT_NEAR(iou_3d(b, a), 1.0 / 3.0, 1e-12) << yaw;
  }
}

TEST(BoxIou, UnitCubesTurned45DegreesGiveTheOctagon) {
  // A unit square and the same square turned 45° about the common centre overlap in a regular octagon. Its side s
  // satisfies 1 = s + 2 s/√2 (a side of the square: one octagon side and two legs of a cut-off right triangle), so
  // s = 1/(1 + √2) = √2 − 1, and its area is 2(1 + √2) s² = 2(√2 − 1) = 2√2 − 2 ≈ 0.8284.
  // IoU = (2√2 − 2) / (1 + 1 − (2√2 − 2)) = (2√2 − 2) / (4 − 2√2) = 1/√2 ≈ 0.7071 (the same heights: 3D = BEV).
  const double octagon = 2.0 * std::sqrt(2.0) - 2.0;
  const Box3D a = box({0.5, -0.25, 0.0}, 1.0, 1.0, 1.0, 0.2);
  const Box3D b = box({0.5, -0.25, 0.0}, 1.0, 1.0, 1.0, 0.2 + std::numbers::pi / 4);
  EXPECT_NEAR(footprint_intersection_area(a, b), octagon, 1e-12);
  EXPECT_NEAR(iou_3d(a, b), octagon / (2.0 - octagon), 1e-12);
  EXPECT_NEAR(bev_iou(a, b), 1.0 / std::sqrt(2.0), 1e-12);
}

TEST(BoxIou, DisjointAndTouchingBoxesGiveZero) {
  const Box3D a = box({0.0, 0.0, 0.0}, 4.0, 2.0, 1.5, 0.4);
  Box3D far = a;
  far.center_bottom.x() += 30.0;
  EXPECT_EQ(iou_3d(a, far), 0.0);
  // Beside each other, sharing a long side (parallel edges on one line).
  Box3D beside = a;
  beside.center_bottom += 2.0 * Vec3(-std::sin(0.4), std::cos(0.4), 0.0);
  EXPECT_NEAR(bev_iou(a, beside), 0.0, 1e-12);
  // Footprints overlap within the circumscribed circles but not in fact (corner to corner, turned).
  const Box3D corner = box({3.2, 3.2, 0.0}, 4.0, 2.0, 1.5, 0.4 + 1.2);
  EXPECT_EQ(bev_iou(box({0, 0, 0}, 4.0, 2.0, 1.5, 0.4), corner), bev_iou(corner, box({0, 0, 0}, 4.0, 2.0, 1.5, 0.4)));
  // Stacked: the same footprint, one box on top of the other.
  Box3D above = a;
  above.center_bottom.z() += 1.5;
  EXPECT_EQ(iou_3d(a, above), 0.0);
  EXPECT_NEAR(bev_iou(a, above), 1.0, 1e-12);
}

TEST(BoxIou, VerticalOffsetScalesOnlyTheHeightOverlap) {
  // Raised by h/4: the overlap is 3/4 of a box, the union 5/4: IoU 0.6; the footprints still coincide.
  const Box3D a = box({5.0, 5.0, -1.0}, 3.0, 1.0, 2.0, 1.0);
  Box3D b = a;
  b.center_bottom.z() += 0.5;
  EXPECT_NEAR(iou_3d(a, b), 0.6, 1e-12);
  EXPECT_NEAR(bev_iou(a, b), 1.0, 1e-12);
}

TEST(BoxIou, NestedAndParallelBoxes) {
  // A 2 x 1 x 1 box inside a 4 x 2 x 2 box, the same yaw and centre off-centre: IoU = 2 / 16.
  const Box3D big = box({0.0, 0.0, 0.0}, 4.0, 2.0, 2.0, 2.0);
  const Box3D small = box({0.3 * std::cos(2.0), 0.3 * std::sin(2.0), 0.5}, 2.0, 1.0, 1.0, 2.0);
  EXPECT_NEAR(iou_3d(big, small), 2.0 / 16.0, 1e-12);
  EXPECT_NEAR(iou_3d(small, big), 2.0 / 16.0, 1e-12);
  // The same yaw, offset along (1 m) and across (0.5 m): overlap (4 - 1)(2 - 0.5) = 4.5 of 8 + 8 - 4.5.
  const Vec3 along(std::cos(2.0), std::sin(2.0), 0.0), across(-std::sin(2.0), std::cos(2.0), 0.0);
  Box3D shifted = big;
  shifted.center_bottom += along + 0.5 * across;
  EXPECT_NEAR(bev_iou(big, shifted), 4.5 / 11.5, 1e-12);
  // Turned by 90° about the common centre: a 2 x 2 square in common, 8 + 8 - 4.
  Box3D turned = big;
  turned.yaw += std::numbers::pi / 2;
  EXPECT_NEAR(bev_iou(big, turned), 4.0 / 12.0, 1e-12);
}

/// Whether p lies inside the box (the same conventions as io::Box3D).
bool contains(const Box3D& b, const Vec3& p) {
  const Vec3 d = p - b.center_bottom;
  const double along = std::cos(b.yaw) * d.x() + std::sin(b.yaw) * d.y();
  const double across = -std::sin(b.yaw) * d.x() + std::cos(b.yaw) * d.y();
  return std::abs(along) <= 0.5 * b.length && std::abs(across) <= 0.5 * b.width && d.z() >= 0.0 && d.z() <= b.height;
}

/// IoU by sampling the axis-aligned box around both: (points in both) / (points in either).
double monte_carlo_iou(const Box3D& a, const Box3D& b, int samples, std::mt19937& rng) {
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (const Box3D* x : {&a, &b}) {
    const double reach = 0.5 * std::hypot(x->length, x->width);
    lo = lo.cwiseMin(x->center_bottom - Vec3(reach, reach, 0.0));
    hi = hi.cwiseMax(x->center_bottom + Vec3(reach, reach, x->height));
  }
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int both = 0, either = 0;
  for (int k = 0; k < samples; ++k) {
    const Vec3 p = lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo);
    const bool in_a = contains(a, p), in_b = contains(b, p);
    both += in_a && in_b ? 1 : 0;
    either += in_a || in_b ? 1 : 0;
  }
  return static_cast<double>(both) / either;
}

TEST(BoxIou, RandomPairsAgreeWithMonteCarloWithinOnePercent) {
  // 2 M samples per pair: for an IoU of 0.2 about 10^5 points in both, a relative standard error near 0.3 %.
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> size(0.5, 5.0), offset(-1.5, 1.5), yaw(-std::numbers::pi, std::numbers::pi), height(-0.5, 0.5);
  int checked = 0;
  while (checked < 12) {
    const Box3D a = box({0.0, 0.0, 0.0}, size(rng), size(rng), size(rng), yaw(rng));
    const Box3D b = box({offset(rng), offset(rng), height(rng)}, size(rng), size(rng), size(rng), yaw(rng));
    const double exact = iou_3d(a, b);
    if (exact < 0.1) continue;  // a relative check needs overlap; disjoint pairs are tested above
    EXPECT_NEAR(monte_carlo_iou(a, b, 2'000'000, rng), exact, 0.01 * exact) << "pair " << checked;
    ++checked;
  }
}

TEST(BoxIou, ClippingAndShoelaceOnKnownPolygons) {
  const std::vector<Vec2> square = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  EXPECT_DOUBLE_EQ(signed_polygon_area(square), 4.0);
  const std::vector<Vec2> triangle = {{1, 1}, {3, 1}, {1, 3}};
  // The triangle x, y >= 1, x + y <= 4 cut by x, y <= 2: the unit square [1, 2]² (its corner (2, 2) has x + y = 4).
  EXPECT_NEAR(signed_polygon_area(clip_to_convex(triangle, square)), 1.0, 1e-12);
  const std::vector<Vec2> apart = {{5, 5}, {6, 5}, {6, 6}};
  EXPECT_TRUE(clip_to_convex(apart, square).empty());
}

}  // namespace
}  // namespace mlidar::eval
