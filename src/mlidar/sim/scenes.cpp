#include "mlidar/sim/scenes.hpp"

#include "mlidar/core/error.hpp"
#include "mlidar/sim/scene_layout.hpp"

namespace mlidar::sim {

std::vector<std::string> scene_names() { return {"corner", "room", "corridor", "campus", "street"}; }

Scene make_scene(const std::string& name, std::uint64_t seed, std::span<const Vec3> path) {
  if (path.empty()) throw UsageError("scene '" + name + "': the path to keep clear is empty");
  if (name == "corner") return layout::corner_scene(seed, path);
  if (name == "room") return layout::room_scene(seed, path);
  if (name == "corridor") return layout::corridor_scene(seed, path);
  if (name == "campus") return layout::campus_scene(seed, path);
  if (name == "street") return layout::street_scene(seed, path);
  throw UsageError("unknown scene '" + name + "' (known: corner, room, corridor, campus, street)");
}

}  // namespace mlidar::sim
