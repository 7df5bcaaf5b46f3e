// Outdoor scenes: campus and street (see scenes.hpp). Objects are placed by
// rejection sampling: a candidate is kept when it clears the path and every
// footprint placed so far (footprints are discs).
#include <cmath>
#include <numbers>

#include "mlidar/sim/scene.hpp"
#include "mlidar/sim/scene_layout.hpp"

namespace mlidar::sim::layout {
namespace {

struct Footprint {
  Eigen::Vector2d centre;
  double radius;
};

class Placer {
 public:
  Placer(std::span<const Vec3> path, Extent2 extent) : path_(path), extent_(extent) {}

  Eigen::Vector2d random_point(std::mt19937_64& rng) const {
    return {uniform(rng, extent_.min.x(), extent_.max.x()), uniform(rng, extent_.min.y(), extent_.max.y())};
  }
  /// Keeps the footprint when it is at least clearance from the path and overlaps nothing placed.
  bool try_place(const Footprint& f, double clearance) {
    if (distance_to_path(path_, f.centre) < f.radius + clearance) return false;
    for (const auto& other : placed_) {
      if ((other.centre - f.centre).norm() < other.radius + f.radius) return false;
    }
    placed_.push_back(f);
    return true;
  }
  void reserve(const Footprint& f) { placed_.push_back(f); }
  const Extent2& extent() const { return extent_; }

 private:
  std::span<const Vec3> path_;
  Extent2 extent_;
  std::vector<Footprint> placed_;
};

void add_buildings(std::mt19937_64& rng, Placer& placer, int count, double clearance, std::vector<Primitive>& out) {
  for (int tries = 0, placed = 0; tries < 40 * count && placed < count; ++tries) {
    // Draws in statements of their own, last argument first (scene_layout.hpp: uniform).
    const double half_z = uniform(rng, 3.0, 10.0), half_y = uniform(rng, 4.0, 12.0), half_x = uniform(rng, 4.0, 15.0);
    const Vec3 half(half_x, half_y, half_z);
    const Eigen::Vector2d xy = placer.random_point(rng);
    if (!placer.try_place({xy, half.head<2>().norm()}, clearance)) continue;
    const double reflectivity = uniform(rng, 0.3, 0.8), yaw = uniform(rng, 0.0, std::numbers::pi);
    out.push_back(make_box(Vec3(xy.x(), xy.y(), half.z()), yaw, half, reflectivity));
    ++placed;
  }
}

void add_trees(std::mt19937_64& rng, Placer& placer, int count, std::vector<Primitive>& out) {
  for (int tries = 0, placed = 0; tries < 20 * count && placed < count; ++tries) {
    const double crown = uniform(rng, 1.2, 2.8);
    const double trunk_height = uniform(rng, 1.8, 3.5);
    const Eigen::Vector2d xy = placer.random_point(rng);
    if (!placer.try_place({xy, crown}, 1.5)) continue;
    out.push_back(make_cylinder(Vec3(xy.x(), xy.y(), trunk_height / 2), uniform(rng, 0.12, 0.3), trunk_height / 2, 0.4));
    out.push_back(make_sphere(Vec3(xy.x(), xy.y(), trunk_height + 0.8 * crown), crown, 0.25));
    ++placed;
  }
}

void add_poles(std::mt19937_64& rng, Placer& placer, int count, std::vector<Primitive>& out) {
  for (int tries = 0, placed = 0; tries < 50 * count && placed < count; ++tries) {
    const Eigen::Vector2d xy = placer.random_point(rng);
    if (!placer.try_place({xy, 0.3}, 2.5)) continue;
    out.push_back(make_cylinder(Vec3(xy.x(), xy.y(), 3.0), 0.08, 3.0, 0.7));
    ++placed;
  }
}

/// Unit heading of the path at sample i (finite difference; +x for a single sample).
Eigen::Vector2d path_heading(std::span<const Vec3> path, std::size_t i) {
  const std::size_t a = i > 0 ? i - 1 : 0;
  const std::size_t b = std::min(path.size() - 1, i + 1);
  const Eigen::Vector2d d = (path[b] - path[a]).head<2>();
  return d.norm() > 1e-9 ? Eigen::Vector2d(d.normalized()) : Eigen::Vector2d::UnitX();
}

/// Cars and pedestrians beside the path: parked cars at 6.5 m either side,
/// oncoming cars in the lane 3.5 m to the left, pedestrians on the sidewalks.
void add_traffic(std::mt19937_64& rng, std::span<const Vec3> path, Placer& placer, std::vector<LabelledObject>& objects) {
  struct Kind {
    const char* type;
    double lateral;
    double speed;
    int count;
    Vec3 size;
  };
  const Kind kinds[] = {{"Car", 6.5, 0.0, 10, Vec3(4.5, 1.8, 1.5)},
                        {"Car", 3.5, -7.0, 3, Vec3(4.6, 1.9, 1.5)},
                        {"Pedestrian", 8.5, 1.3, 6, Vec3(0.6, 0.6, 1.75)}};
  std::uniform_int_distribution<std::size_t> sample(0, path.size() - 1);
  for (const auto& kind : kinds) {
    for (int tries = 0, placed = 0; tries < 30 * kind.count && placed < kind.count; ++tries) {
      const std::size_t i = sample(rng);
      const Eigen::Vector2d heading = path_heading(path, i);
      const double side = kind.speed == 0.0 && uniform(rng, 0.0, 1.0) < 0.5 ? -1.0 : 1.0;
      const Eigen::Vector2d left(-heading.y(), heading.x());
      const Eigen::Vector2d xy = path[i].head<2>() + side * kind.lateral * left + uniform(rng, -3.0, 3.0) * heading;
      const double scale_z = uniform(rng, 0.9, 1.1), scale_y = uniform(rng, 0.9, 1.1), scale_x = uniform(rng, 0.9, 1.1);
      const Vec3 size = kind.size.cwiseProduct(Vec3(scale_x, scale_y, scale_z));
      const double radius = 0.5 * size.head<2>().norm();
      if (!placer.try_place({xy, radius}, kind.lateral - 1.0 - radius)) continue;
      LabelledObject object;
      object.id = static_cast<int>(objects.size()) + 1;
      object.type = kind.type;
      object.centre = Vec3(xy.x(), xy.y(), size.z() / 2);
      object.size = size;
      object.yaw = std::atan2(heading.y(), heading.x());
      object.velocity = kind.speed * Vec3(heading.x(), heading.y(), 0.0);
      objects.push_back(object);
      ++placed;
    }
  }
}

int scaled_count(const Extent2& e, double area_per_item) {
  return static_cast<int>(std::clamp((e.max - e.min).prod() / area_per_item, 4.0, 400.0));
}

}  // namespace

Scene campus_scene(std::uint64_t seed, std::span<const Vec3> path) {
  std::mt19937_64 rng(seed);
  Placer placer(path, path_extent(path, 60.0));
  // Gentle slope (a few mm per metre) through the origin.
  const double slope_y = uniform(rng, -0.003, 0.003), slope_x = uniform(rng, -0.003, 0.003);
  std::vector<Primitive> primitives{make_ground(0.0, Eigen::Vector2d(slope_x, slope_y), 0.3)};
  add_buildings(rng, placer, scaled_count(placer.extent(), 1500.0), 5.0, primitives);
  add_trees(rng, placer, scaled_count(placer.extent(), 250.0), primitives);
  add_poles(rng, placer, scaled_count(placer.extent(), 800.0), primitives);
  return Scene("campus", primitives, {});
}

Scene street_scene(std::uint64_t seed, std::span<const Vec3> path) {
  std::mt19937_64 rng(seed);
  Placer placer(path, path_extent(path, 50.0));
  std::vector<Primitive> primitives{make_ground(0.0, Eigen::Vector2d::Zero(), 0.3)};
  std::vector<LabelledObject> objects;
  add_traffic(rng, path, placer, objects);
  add_buildings(rng, placer, scaled_count(placer.extent(), 700.0), 11.0, primitives);
  add_trees(rng, placer, scaled_count(placer.extent(), 600.0), primitives);
  add_poles(rng, placer, scaled_count(placer.extent(), 600.0), primitives);
  for (const auto& object : objects) primitives.push_back(object_box(object, object.type == std::string("Car") ? 0.8 : 0.4));
  return Scene("street", primitives, std::move(objects));
}

}  // namespace mlidar::sim::layout
