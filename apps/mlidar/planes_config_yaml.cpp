#include "apps/mlidar/planes_config_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include "mlidar/core/error.hpp"

namespace mlidar::cli {
namespace {

template <typename T>
T value_of(const YAML::Node& node, const std::string& key, const std::string& source) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw UsageError(source + ": " + key + ": wrong type of value");
  }
}

}  // namespace

calib::PlanesConfig parse_planes_config(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw UsageError(source + ": not valid YAML: " + e.what());
  }
  calib::PlanesConfig config;
  if (root.IsNull()) return config;
  if (!root.IsMap()) throw UsageError(source + ": expected a map of planes settings");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    const YAML::Node& v = entry.second;
    if (key == "inlier_distance") config.inlier_distance = value_of<double>(v, key, source);
    else if (key == "ransac_iterations") config.ransac_iterations = value_of<int>(v, key, source);
    else if (key == "max_planes") config.max_planes = value_of<int>(v, key, source);
    else if (key == "min_plane_points") config.min_plane_points = value_of<std::size_t>(v, key, source);
    else if (key == "min_corner_angle_deg") config.min_corner_angle_deg = value_of<double>(v, key, source);
    else if (key == "min_any_angle_deg") config.min_any_angle_deg = value_of<double>(v, key, source);
    else if (key == "corner_max_gap") config.corner_max_gap = value_of<double>(v, key, source);
    else if (key == "warn_min_inliers") config.warn_min_inliers = value_of<std::size_t>(v, key, source);
    else if (key == "max_points_per_plane") config.max_points_per_plane = value_of<std::size_t>(v, key, source);
    else if (key == "huber_delta") config.huber_delta = value_of<double>(v, key, source);
    else if (key == "max_iterations") config.max_iterations = value_of<int>(v, key, source);
    else if (key == "max_rotation_sigma_deg") config.max_rotation_sigma_deg = value_of<double>(v, key, source);
    else if (key == "seed") config.seed = value_of<std::uint64_t>(v, key, source);
    else if (key == "up") {
      const auto up = value_of<std::vector<double>>(v, key, source);
      if (up.size() != 3) throw UsageError(source + ": up: expected [x, y, z]");
      config.up = Vec3(up[0], up[1], up[2]);
    } else {
      throw UsageError(source + ": unknown key '" + key + "' (see docs: PlanesConfig)");
    }
  }
  return config;
}

}  // namespace mlidar::cli
