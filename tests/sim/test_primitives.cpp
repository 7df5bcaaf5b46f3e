// Ray casting against analytic intersections, and the grid against brute force.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/sim/primitives.hpp"
#include "mlidar/sim/scene.hpp"
#include "mlidar/sim/uniform_grid.hpp"

namespace mlidar::sim {
namespace {

Ray make_ray(const Vec3& origin, const Vec3& toward) { return {origin, (toward - origin).normalized()}; }

TEST(Primitives, SphereHitEqualsDistanceMinusRadius) {
  const Primitive sphere = make_sphere(Vec3(3.0, -2.0, 1.5), 0.7, 0.5);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (int i = 0; i < 100; ++i) {
    const Vec3 origin(u(rng), u(rng), u(rng));
    if ((origin - sphere.centre).norm() < 1.0) continue;
    const auto hit = intersect(sphere, make_ray(origin, sphere.centre), 0.0, 1e3);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, (origin - sphere.centre).norm() - 0.7, 1e-9);
    EXPECT_NEAR(hit->normal.dot((sphere.centre - origin).normalized()), -1.0, 1e-9);
  }
}

TEST(Primitives, SphereOffCentreChordMatchesPythagoras) {
  // Ray along x at height b from the centre: t = D - sqrt(r^2 - b^2).
  const Primitive sphere = make_sphere(Vec3(5.0, 0.0, 0.0), 2.0, 0.5);
  const Ray ray{Vec3(0.0, 0.0, 1.2), Vec3::UnitX()};
  const auto hit = intersect(sphere, ray, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 5.0 - std::sqrt(4.0 - 1.44), 1e-12);
  EXPECT_FALSE(intersect(sphere, Ray{Vec3(0.0, 0.0, 2.1), Vec3::UnitX()}, 0.0, 100.0));
  EXPECT_FALSE(intersect(sphere, ray, 0.0, 2.0));  // beyond t_max
}

TEST(Primitives, RotatedBoxFaceDistance) {
  const double yaw = 0.6;
  const Primitive box = make_box(Vec3(10.0, 4.0, 1.0), yaw, Vec3(2.0, 1.0, 1.0), 0.5);
  // A ray along the box's -x axis toward its centre hits the +x face at distance D - 2.
  const Vec3 axis(std::cos(yaw), std::sin(yaw), 0.0);
  const Vec3 origin = box.centre + 9.0 * axis + Vec3(0.0, 0.0, 0.3);
  const auto hit = intersect(box, Ray{origin, -axis}, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 7.0, 1e-9);
  EXPECT_NEAR(hit->normal.dot(axis), 1.0, 1e-9);
  // From inside, the ray exits through the far face.
  const auto inside = intersect(box, Ray{box.centre, axis}, 0.0, 100.0);
  ASSERT_TRUE(inside);
  EXPECT_NEAR(inside->t, 2.0, 1e-9);
}

TEST(Primitives, CylinderSideAndCap) {
  const Primitive cyl = make_cylinder(Vec3(0.0, 5.0, 2.0), 0.5, 2.0, 0.5);
  const Ray side{Vec3(0.0, 0.0, 1.0), Vec3::UnitY()};
  auto hit = intersect(cyl, side, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 4.5, 1e-12);
  const Ray down{Vec3(0.2, 5.1, 10.0), -Vec3::UnitZ()};
  hit = intersect(cyl, down, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 6.0, 1e-12);  // top cap at z = 4
  EXPECT_NEAR(hit->normal.z(), 1.0, 1e-12);
  // Oblique ray: the hit point lies on the side surface at radius 0.5.
  const Ray oblique = make_ray(Vec3(-3.0, 1.0, 0.5), Vec3(0.1, 5.0, 2.5));
  hit = intersect(cyl, oblique, 0.0, 100.0);
  ASSERT_TRUE(hit);
  const Vec3 p = oblique.origin + hit->t * oblique.direction;
  EXPECT_NEAR(std::hypot(p.x(), p.y() - 5.0), 0.5, 1e-9);
}

TEST(Primitives, RectangleAndSlopedGround) {
  Mat3 axes;
  axes << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // u = y, v = z, normal = x: a wall at x = 6
  const Primitive wall = make_rectangle(Vec3(6.0, 0.0, 1.0), axes, 2.0, 1.0, 0.5);
  const Ray ray = make_ray(Vec3::Zero(), Vec3(6.0, 1.0, 0.5));
  auto hit = intersect(wall, ray, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, std::sqrt(36.0 + 1.0 + 0.25), 1e-12);
  EXPECT_FALSE(intersect(wall, make_ray(Vec3::Zero(), Vec3(6.0, 2.5, 0.5)), 0.0, 100.0));

  const Primitive ground = make_ground(-1.0, Eigen::Vector2d(0.02, -0.01), 0.3);
  const Ray down = make_ray(Vec3(0.0, 0.0, 1.0), Vec3(10.0, 3.0, -1.0));
  hit = intersect(ground, down, 0.0, 1e3);
  ASSERT_TRUE(hit);
  const Vec3 p = down.origin + hit->t * down.direction;
  EXPECT_NEAR(p.z(), -1.0 + 0.02 * p.x() - 0.01 * p.y(), 1e-9);
}

Primitive random_primitive(std::mt19937_64& rng, int index) {
  std::uniform_real_distribution<double> pos(-40.0, 40.0);
  std::uniform_real_distribution<double> size(0.2, 3.0);
  const Vec3 centre(pos(rng), pos(rng), size(rng));
  switch (index % 4) {
    case 0:
      return make_box(centre, pos(rng), Vec3(size(rng), size(rng), size(rng)), 0.5);
    case 1:
      return make_cylinder(centre, size(rng) * 0.3, size(rng), 0.5);
    case 2:
      return make_sphere(centre, size(rng) * 0.5, 0.5);
    default: {
      const Mat3 axes = Eigen::AngleAxisd(pos(rng), Vec3(0.3, 0.4, 1.0).normalized()).toRotationMatrix();
      return make_rectangle(centre, axes, size(rng), size(rng), 0.5);
    }
  }
}

TEST(UniformGrid, MatchesBruteForce) {
  std::mt19937_64 rng(7);
  std::vector<Primitive> primitives;
  for (int i = 0; i < 300; ++i) primitives.push_back(random_primitive(rng, i));
  const UniformGrid grid(primitives, 2.0);
  std::uniform_real_distribution<double> pos(-50.0, 50.0);
  std::uniform_real_distribution<double> z(-2.0, 6.0);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    const Ray ray = make_ray(Vec3(pos(rng), pos(rng), z(rng)), Vec3(pos(rng), pos(rng), z(rng)));
    std::optional<Hit> expected;
    for (const auto& p : primitives) {
      auto hit = intersect(p, ray, 0.0, 80.0);
      if (hit && (!expected || hit->t < expected->t)) expected = hit;
    }
    const auto actual = grid.cast(ray, 0.0, 80.0);
    ASSERT_EQ(expected.has_value(), actual.has_value()) << "ray " << i;
    if (expected) {
      ++hits;
      EXPECT_NEAR(actual->t, expected->t, 1e-12);
    }
  }
  EXPECT_GT(hits, 300);
}

TEST(Scene, MovingObjectIsHitWhereItIsAtTheRayTime) {
  LabelledObject car{1, "Car", Vec3(10.0, 0.0, 0.75), Vec3(4.0, 2.0, 1.5), 0.0, Vec3(2.0, 0.0, 0.0)};
  const Scene scene("test", {object_box(car, 0.6), make_ground(0.0, Eigen::Vector2d::Zero(), 0.3)}, {car});
  const Ray ray{Vec3(0.0, 0.0, 0.75), Vec3::UnitX()};
  for (const double t : {0.0, 0.5, 1.0}) {
    const auto hit = scene.cast(ray, 0.0, 100.0, t);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 8.0 + 2.0 * t, 1e-12);
    EXPECT_EQ(hit->object_id, 1);
    EXPECT_TRUE(car.contains(ray.origin + hit->t * ray.direction, t, 1e-9));
  }
}

}  // namespace
}  // namespace mlidar::sim
