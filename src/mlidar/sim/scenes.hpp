#pragma once
// Named scenes generated from a seed around the path the rig will travel (so
// nothing is placed on it). The ground is z = 0 (campus: a gentle slope).
//   corner   : a wall corner: two perpendicular walls and the ground
//   room     : four walls, floor, ceiling, furniture boxes and pillars
//   corridor : two long parallel walls, floor and ceiling; its ends lie
//              beyond every sensor's range, so it is degenerate along its axis
//   campus   : buildings, trees (trunk cylinder + crown sphere), poles, lawns
//   street   : buildings along the path, parked and moving cars and walking
//              pedestrians as labelled boxes (LabelledObject)
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mlidar/sim/scene.hpp"

namespace mlidar::sim {

std::vector<std::string> scene_names();

/// path: world positions of the rig's base over the run (at least one).
/// Throws UsageError for an unknown name.
Scene make_scene(const std::string& name, std::uint64_t seed, std::span<const Vec3> path);

}  // namespace mlidar::sim
