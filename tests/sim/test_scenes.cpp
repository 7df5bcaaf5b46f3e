// Scenes: deterministic from the seed, clear of the path, labelled objects valid.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/sim/scenes.hpp"

namespace mlidar::sim {
namespace {

std::vector<Vec3> curved_path() {
  std::vector<Vec3> path;
  for (int i = 0; i <= 60; ++i) path.emplace_back(i * 1.0, 4.0 * std::sin(i * 0.05), 1.5);
  return path;
}

TEST(Scenes, SameSeedSameSceneDifferentSeedDifferentScene) {
  const auto path = curved_path();
  for (const auto& name : scene_names()) {
    const auto a = make_scene(name, 5, path).primitives();
    const auto b = make_scene(name, 5, path).primitives();
    const auto c = make_scene(name, 6, path).primitives();
    ASSERT_EQ(a.size(), b.size()) << name;
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].centre, b[i].centre) << name;
    bool differs = a.size() != c.size();
    for (std::size_t i = 0; !differs && i < a.size(); ++i) differs = a[i].centre != c[i].centre || a[i].half_extent != c[i].half_extent;
    EXPECT_TRUE(differs) << name;
  }
}

TEST(Scenes, PathIsClearAndSurroundedBySurfaces) {
  const auto path = curved_path();
  for (const auto& name : scene_names()) {
    const Scene scene = make_scene(name, 3, path);
    for (std::size_t i = 0; i < path.size(); i += 5) {
      for (int k = 0; k < 12; ++k) {
        const double a = 2.0 * std::numbers::pi * k / 12;
        const Ray ray{path[i], Vec3(std::cos(a), std::sin(a), 0.0)};
        const auto hit = scene.cast(ray, 0.0, 500.0, 0.0);
        if (hit) {
          EXPECT_GT(hit->t, 0.9) << name << " sample " << i;
        }
      }
      const auto down = scene.cast(Ray{path[i], -Vec3::UnitZ()}, 0.0, 10.0, 0.0);
      ASSERT_TRUE(down) << name;
      EXPECT_NEAR(down->t, 1.5, 0.3) << name;  // the ground, gently sloped on campus
    }
  }
}

TEST(Scenes, StreetHasLabelledCarsAndPedestrians) {
  const Scene scene = make_scene("street", 2, curved_path());
  int cars = 0;
  int pedestrians = 0;
  int moving = 0;
  for (std::size_t i = 0; i < scene.objects().size(); ++i) {
    const auto& object = scene.objects()[i];
    EXPECT_EQ(object.id, static_cast<int>(i) + 1);
    cars += object.type == "Car";
    pedestrians += object.type == "Pedestrian";
    moving += object.velocity.norm() > 0.0;
    EXPECT_NEAR(object.centre.z(), object.size.z() / 2, 1e-12);
  }
  EXPECT_GT(cars, 3);
  EXPECT_GT(pedestrians, 1);
  EXPECT_GT(moving, 1);
}

TEST(Scenes, UnknownNameIsAUsageError) {
  const auto path = curved_path();
  EXPECT_THROW(make_scene("forest", 1, path), UsageError);
}

}  // namespace
}  // namespace mlidar::sim
