#pragma once
// One street scene for 3D object detection, seen from a vehicle standing at
// the origin of the world frame (x forward, y left, z up, the ground at z = 0).
// A road along x (2-4 lanes, the vehicle in a right-hand lane), kerbs, raised
// sidewalks, building fronts with gaps, sometimes a cross street, clutter that
// is no object of interest (poles, trees, bins, benches, parked containers,
// hedges), and labelled cars, pedestrians and cyclists (sim/object_shapes.hpp):
// parked and driving cars (both directions, some turning or on the cross street),
// pedestrians on the sidewalks and crossing, cyclists at the road's edge.
// Objects stand up to 70 m away (beyond the 50 m of the hardest difficulty),
// hide each other and get hidden by the clutter. The same seed gives the same scene.
#include <cstdint>

#include "mlidar/sim/scene.hpp"

namespace mlidar::sim {

/// The street scene for `seed`; objects are numbered 1, 2, ... (Scene::objects()[id - 1]).
Scene detection_scene(std::uint64_t seed);
/// A quick scene for tests and first looks: 3-6 cars standing apart on open ground, 6 to 25 m away, heading along or
/// across (within 11.5°) as on roads, nothing else (no street, clutter, pedestrians or cyclists).
Scene cars_scene(std::uint64_t seed);

}  // namespace mlidar::sim
