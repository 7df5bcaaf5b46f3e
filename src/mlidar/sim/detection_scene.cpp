#include "mlidar/sim/detection_scene.hpp"

#include <cmath>
#include <numbers>
#include <optional>

#include "mlidar/sim/object_shapes.hpp"
#include "mlidar/sim/scene_layout.hpp"

namespace mlidar::sim {
namespace {

using layout::uniform;
constexpr double kPi = std::numbers::pi;
constexpr double kReach = 70.0;  ///< objects and scenery from -kReach to kReach along the road
constexpr double kSidewalkHeight = 0.15;

/// The street's cross-section (y of the vehicle frame) and its cross street.
struct Street {
  double road_left = 0.0;   ///< kerb line left of the vehicle (y > 0)
  double road_right = 0.0;  ///< kerb line right of the vehicle (y < 0)
  double sidewalk = 3.0;    ///< sidewalk width beyond each kerb
  std::optional<double> cross_x;
  double cross_half_width = 0.0;

  bool in_cross_street(double x, double margin = 0.0) const { return cross_x && std::abs(x - *cross_x) < cross_half_width + margin; }
};

/// Footprints (discs) of everything placed on the ground, so nothing overlaps.
class Footprints {
 public:
  bool free(const Eigen::Vector2d& xy, double radius) const {
    // The vehicle itself (its LiDARs sit from x = 1.2 to 3.5 m) and a metre around it.
    if (xy.x() > -2.5 - radius && xy.x() < 6.5 + radius && std::abs(xy.y()) < 2.2 + radius) return false;
    for (const auto& [centre, r] : discs_) {
      if ((centre - xy).norm() < r + radius) return false;
    }
    return true;
  }
  void add(const Eigen::Vector2d& xy, double radius) { discs_.emplace_back(xy, radius); }

 private:
  std::vector<std::pair<Eigen::Vector2d, double>> discs_;
};

Street make_street(std::mt19937_64& rng) {
  Street street;
  const double lanes_left = std::floor(uniform(rng, 1.0, 3.0));
  const double lane = uniform(rng, 3.0, 3.6);
  street.road_right = -uniform(rng, 0.5 * lane + 0.5, 0.5 * lane + 1.5);  // a parking strip on the right
  street.road_left = (lanes_left + 0.5) * lane + uniform(rng, 0.0, 1.5);
  street.sidewalk = uniform(rng, 2.5, 5.0);
  if (uniform(rng, 0.0, 1.0) < 0.4) {
    const double side = uniform(rng, 0.0, 1.0) < 0.3 ? -1.0 : 1.0;
    street.cross_x = side * uniform(rng, 15.0, 45.0);
    street.cross_half_width = uniform(rng, 4.0, 7.0);
  }
  return street;
}

/// Kerb stones and raised sidewalks both sides, cut where the cross street passes.
void add_sidewalks(const Street& street, std::vector<Primitive>& out) {
  std::vector<std::pair<double, double>> spans{{-kReach - 10, kReach + 10}};
  if (street.cross_x) {
    spans = {{-kReach - 10, *street.cross_x - street.cross_half_width}, {*street.cross_x + street.cross_half_width, kReach + 10}};
  }
  for (const auto& [x0, x1] : spans) {
    const double cx = (x0 + x1) / 2, half_x = (x1 - x0) / 2;
    for (const double kerb : {street.road_left, street.road_right}) {
      const double outward = kerb > 0 ? 1.0 : -1.0;
      out.push_back(make_box(Vec3(cx, kerb + outward * street.sidewalk / 2, kSidewalkHeight / 2), 0.0,
                             Vec3(half_x, street.sidewalk / 2, kSidewalkHeight / 2), 0.35));
    }
  }
}

/// Building fronts beyond the sidewalks, with gaps between buildings.
void add_buildings(std::mt19937_64& rng, const Street& street, std::vector<Primitive>& out) {
  for (const double kerb : {street.road_left, street.road_right}) {
    const double outward = kerb > 0 ? 1.0 : -1.0;
    for (double x = -kReach - 10; x < kReach + 10;) {
      const double length = uniform(rng, 8.0, 35.0);
      const double setback = uniform(rng, 0.0, 6.0);
      const double height = uniform(rng, 4.0, 20.0);
      const double depth = uniform(rng, 8.0, 15.0);
      const double gap = uniform(rng, 0.0, 8.0);
      const double cx = x + length / 2;
      if (!street.in_cross_street(cx, length / 2 + 1.0)) {
        const double y = kerb + outward * (street.sidewalk + setback + depth / 2);
        out.push_back(make_box(Vec3(cx, y, height / 2), 0.0, Vec3(length / 2, depth / 2, height / 2), uniform(rng, 0.3, 0.8)));
      }
      x += length + gap;
    }
  }
}

/// Poles, trees, bins and benches on the sidewalks; hedges and parked containers at their back.
void add_clutter(std::mt19937_64& rng, const Street& street, Footprints& footprints, std::vector<Primitive>& out) {
  const int count = static_cast<int>(uniform(rng, 25.0, 60.0));
  for (int i = 0; i < count; ++i) {
    const double kind = uniform(rng, 0.0, 1.0);
    const double side = uniform(rng, 0.0, 1.0) < 0.5 ? 1.0 : -1.0;
    const double depth = uniform(rng, 0.3, street.sidewalk - 0.3);
    const double x = uniform(rng, -kReach, kReach);
    const double kerb = side > 0 ? street.road_left : street.road_right;
    const Eigen::Vector2d xy(x, kerb + side * depth);
    const double radius = kind < 0.55 ? 0.3 : kind < 0.75 ? 1.5 : 1.2;
    if (street.in_cross_street(x, radius) || !footprints.free(xy, radius)) continue;
    footprints.add(xy, radius);
    if (kind < 0.35) {
      out.push_back(make_cylinder(Vec3(xy.x(), xy.y(), 3.0), uniform(rng, 0.06, 0.12), 3.0, 0.7));  // pole
    } else if (kind < 0.55) {
      out.push_back(make_box(Vec3(xy.x(), xy.y(), 0.5), uniform(rng, 0.0, kPi), Vec3(0.3, 0.3, 0.5), 0.5));  // bin
    } else if (kind < 0.75) {
      const double trunk = uniform(rng, 1.8, 3.0);
      const double crown = uniform(rng, 1.0, 2.2);
      out.push_back(make_cylinder(Vec3(xy.x(), xy.y(), trunk / 2), 0.15, trunk / 2, 0.4));
      out.push_back(make_sphere(Vec3(xy.x(), xy.y(), trunk + 0.8 * crown), crown, 0.25));
    } else if (kind < 0.9) {
      out.push_back(make_box(Vec3(xy.x(), xy.y(), 0.45), 0.0, Vec3(0.9, 0.3, 0.45), 0.45));  // bench
    } else {
      const double back = kerb + side * (street.sidewalk - 0.6);
      out.push_back(make_box(Vec3(xy.x(), back, 0.75), 0.0, Vec3(uniform(rng, 1.0, 3.0), 0.5, 0.75), 0.3));  // hedge / container
    }
  }
}

/// Where and how an object of a class is placed: on the road (lanes, parking strip, cross street) for cars,
/// on the sidewalks or crossing for pedestrians, at the road's edge for cyclists.
struct Placement {
  Eigen::Vector2d xy;
  double yaw;
  double ground_z = 0.0;  ///< 0 on the road, the sidewalk's top on it
};

Placement car_placement(std::mt19937_64& rng, const Street& street) {
  const double where = uniform(rng, 0.0, 1.0);
  const double x = uniform(rng, -kReach, kReach);
  const double flip = uniform(rng, 0.0, 1.0) < 0.5 ? 0.0 : kPi;
  const double jitter = uniform(rng, -0.06, 0.06);
  if (where < 0.3) return {{x, street.road_right + 1.1}, flip + jitter};                                        // parked, right strip
  if (where < 0.5) return {{x, street.road_left - 1.1}, flip + jitter};                                         // parked, left kerb
  if (where < 0.8) return {{x, uniform(rng, street.road_right + 2.5, street.road_left - 2.5)}, flip + jitter};  // driving
  if (street.cross_x && where < 0.92)
    return {{*street.cross_x + uniform(rng, -0.6, 0.6) * street.cross_half_width, uniform(rng, -kReach / 2, kReach / 2)},
            flip + kPi / 2 + jitter};                                                                    // on the cross street
  return {{x, uniform(rng, street.road_right + 1.5, street.road_left - 1.5)}, uniform(rng, -kPi, kPi)};  // turning
}

Placement pedestrian_placement(std::mt19937_64& rng, const Street& street) {
  const double where = uniform(rng, 0.0, 1.0);
  const double x = uniform(rng, -kReach, kReach);
  if (where < 0.2) return {{x, uniform(rng, street.road_right, street.road_left)}, uniform(rng, 0.0, 1.0) < 0.5 ? kPi / 2 : -kPi / 2};
  const double side = where < 0.6 ? 1.0 : -1.0;
  const double kerb = side > 0 ? street.road_left : street.road_right;
  return {{x, kerb + side * uniform(rng, 0.4, street.sidewalk - 0.4)}, uniform(rng, -kPi, kPi), kSidewalkHeight};
}

Placement cyclist_placement(std::mt19937_64& rng, const Street& street) {
  const double where = uniform(rng, 0.0, 1.0);
  const double x = uniform(rng, -kReach, kReach);
  const double flip = uniform(rng, 0.0, 1.0) < 0.5 ? 0.0 : kPi;
  const double jitter = uniform(rng, -0.15, 0.15);
  if (where < 0.45) return {{x, street.road_right + 0.8}, flip + jitter};
  if (where < 0.8) return {{x, street.road_left - 0.8}, flip + jitter};
  const double kerb = where < 0.9 ? street.road_left : street.road_right;
  return {{x, kerb + (kerb > 0 ? 1.0 : -1.0) * uniform(rng, 0.5, 1.5)}, uniform(rng, -kPi, kPi), kSidewalkHeight};
}

/// Puts `object` into the scene when its footprint (a disc `clearance` wider than its box) is free; false otherwise.
bool place(const ShapedObject& object, double clearance, Footprints& footprints, std::vector<Primitive>& primitives,
           std::vector<LabelledObject>& objects) {
  const double radius = 0.5 * object.label.size.head<2>().norm() + clearance;
  const Eigen::Vector2d centre = object.label.centre.head<2>();
  if (!footprints.free(centre, radius)) return false;
  footprints.add(centre, radius);
  primitives.insert(primitives.end(), object.parts.begin(), object.parts.end());
  objects.push_back(object.label);
  return true;
}

void add_objects(std::mt19937_64& rng, const Street& street, Footprints& footprints, std::vector<Primitive>& primitives,
                 std::vector<LabelledObject>& objects) {
  struct Quota {
    ObjectClass object_class;
    int count;
  };
  const int cars = static_cast<int>(uniform(rng, 8.0, 24.0));
  const int pedestrians = static_cast<int>(uniform(rng, 3.0, 12.0));
  const int cyclists = static_cast<int>(uniform(rng, 1.0, 6.0));
  for (const Quota& quota : {Quota{ObjectClass::kCar, cars}, {ObjectClass::kPedestrian, pedestrians}, {ObjectClass::kCyclist, cyclists}}) {
    for (int tries = 0, placed = 0; tries < 20 * quota.count && placed < quota.count; ++tries) {
      const Placement at = quota.object_class == ObjectClass::kCar          ? car_placement(rng, street)
                           : quota.object_class == ObjectClass::kPedestrian ? pedestrian_placement(rng, street)
                                                                            : cyclist_placement(rng, street);
      const ShapedObject object = make_shaped_object(quota.object_class, Vec3(at.xy.x(), at.xy.y(), at.ground_z), at.yaw,
                                                     static_cast<int>(objects.size()) + 1, rng);
      if (place(object, 0.2, footprints, primitives, objects)) ++placed;
    }
  }
}

}  // namespace

Scene detection_scene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Street street = make_street(rng);
  std::vector<Primitive> primitives{make_ground(0.0, Eigen::Vector2d::Zero(), 0.3)};
  add_sidewalks(street, primitives);
  add_buildings(rng, street, primitives);
  Footprints footprints;
  add_clutter(rng, street, footprints, primitives);
  std::vector<LabelledObject> objects;
  add_objects(rng, street, footprints, primitives, objects);
  return Scene("detection-street", primitives, std::move(objects));
}

Scene cars_scene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Primitive> primitives{make_ground(0.0, Eigen::Vector2d::Zero(), 0.3)};
  std::vector<LabelledObject> objects;
  Footprints footprints;
  const int cars = static_cast<int>(uniform(rng, 3.0, 7.0));
  for (int tries = 0; tries < 50 * cars && static_cast<int>(objects.size()) < cars; ++tries) {
    const double range = uniform(rng, 6.0, 25.0), bearing = uniform(rng, -kPi, kPi);
    const double heading = std::floor(uniform(rng, 0.0, 4.0)) * kPi / 2 + uniform(rng, -0.2, 0.2);  // along or across a road
    place(make_shaped_object(ObjectClass::kCar, Vec3(range * std::cos(bearing), range * std::sin(bearing), 0.0), heading,
                             static_cast<int>(objects.size()) + 1, rng),
          1.0, footprints, primitives, objects);
  }
  return Scene("detection-cars", primitives, std::move(objects));
}

}  // namespace mlidar::sim
