// Rig YAML parsing (schema in rig.hpp). Every error names the source and the key.
#include <algorithm>
#include <cmath>
#include <regex>
#include <set>

#include <yaml-cpp/yaml.h>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/yaml_fields.hpp"
#include "mlidar/sim/lidar_models.hpp"
#include "mlidar/sim/rig.hpp"

namespace mlidar::sim {
namespace {

// The rig YAML schema (see rig.hpp) on top of the generic strict accessors.
class Reader : public io::YamlFields {
 public:
  explicit Reader(std::string source) : YamlFields(std::move(source), "rig YAML") {}

  LidarModel model(const YAML::Node& node, const std::string& key) const {
    if (node.IsScalar()) {
      try {
        return lidar_model(node.as<std::string>());
      } catch (const UsageError& e) {
        fail(key, e.what());
      }
    }
    only_keys(node, key,
              {"name", "vertical_angles_deg", "horizontal_resolution_deg", "min_range", "max_range", "range_noise_sigma", "sweep_period"});
    LidarModel model;
    model.name = node["name"] ? text(node["name"], key + ".name") : "custom";
    if (!node["vertical_angles_deg"]) fail(key + ".vertical_angles_deg", "missing (one elevation per ring, degrees)");
    model.vertical_angles_deg = numbers(node["vertical_angles_deg"], key + ".vertical_angles_deg", 0);
    for (const double a : model.vertical_angles_deg) {
      if (std::abs(a) > 90.0) fail(key + ".vertical_angles_deg", "elevations must lie in [-90, 90] degrees");
    }
    if (model.vertical_angles_deg.size() > 65535) fail(key + ".vertical_angles_deg", "at most 65535 rings");
    std::sort(model.vertical_angles_deg.begin(), model.vertical_angles_deg.end());
    if (node["horizontal_resolution_deg"])
      model.horizontal_resolution_deg = number_in(node["horizontal_resolution_deg"], key + ".horizontal_resolution_deg", 0.01, 360.0);
    if (node["min_range"]) model.min_range = number_in(node["min_range"], key + ".min_range", 0.0, 1e4);
    if (node["max_range"]) model.max_range = number_in(node["max_range"], key + ".max_range", 0.0, 1e4);
    if (model.max_range <= model.min_range) fail(key + ".max_range", "must exceed min_range");
    if (node["range_noise_sigma"]) model.range_noise_sigma = number_in(node["range_noise_sigma"], key + ".range_noise_sigma", 0.0, 10.0);
    if (node["sweep_period"]) model.sweep_period = number_in(node["sweep_period"], key + ".sweep_period", 1e-3, 10.0);
    return model;
  }

  SimLidar lidar(const YAML::Node& node, const std::string& key) const {
    only_keys(node, key, {"name", "model", "translation", "rotation_rpy_deg", "quaternion_wxyz", "dropout", "sweep_offset"});
    SimLidar lidar;
    lidar.name = text(node["name"], key + ".name");
    if (!std::regex_match(lidar.name, std::regex("[A-Za-z0-9_-]+")))
      fail(key + ".name", "use letters, digits, '_' or '-' (it names the scan folder)");
    if (!node["model"]) fail(key + ".model", "missing (a model name or a mapping)");
    lidar.model = model(node["model"], key + ".model");
    Vec3 t = Vec3::Zero();
    if (node["translation"]) t = Vec3(numbers(node["translation"], key + ".translation", 3).data());
    Quat q = Quat::Identity();
    if (node["rotation_rpy_deg"] && node["quaternion_wxyz"]) fail(key, "give rotation_rpy_deg or quaternion_wxyz, not both");
    if (node["rotation_rpy_deg"]) {
      const auto rpy = numbers(node["rotation_rpy_deg"], key + ".rotation_rpy_deg", 3);
      q = quat_from_rpy_deg(Vec3(rpy[0], rpy[1], rpy[2]));
    } else if (node["quaternion_wxyz"]) {
      const auto w = numbers(node["quaternion_wxyz"], key + ".quaternion_wxyz", 4);
      q = Quat(w[0], w[1], w[2], w[3]);
      if (std::abs(q.norm() - 1.0) > 1e-6) fail(key + ".quaternion_wxyz", "expected a unit quaternion (norm 1 within 1e-6)");
      q.normalize();
    }
    lidar.T_base_lidar = SE3(q, t);
    if (node["dropout"]) lidar.dropout_probability = number_in(node["dropout"], key + ".dropout", 0.0, 0.999);
    if (node["sweep_offset"]) {
      lidar.sweep_offset = number_in(node["sweep_offset"], key + ".sweep_offset", 0.0, lidar.model.sweep_period);
      if (lidar.sweep_offset >= lidar.model.sweep_period) fail(key + ".sweep_offset", "must be below the sweep period");
    }
    return lidar;
  }
};

}  // namespace

SimRig parse_rig_yaml(const std::string& text, const std::string& source) {
  const Reader reader(source);
  const YAML::Node root = reader.load(text);
  reader.only_keys(root, "", {"name", "base", "base_height", "lidars"});
  SimRig rig;
  rig.name = root["name"] ? reader.text(root["name"], "name") : "custom";
  if (root["base_height"]) rig.base_height = reader.number_in(root["base_height"], "base_height", -100.0, 100.0);
  const YAML::Node lidars = root["lidars"];
  if (!lidars || !lidars.IsSequence() || lidars.size() == 0) reader.fail("lidars", "expected a non-empty list of LiDARs");
  std::set<std::string> names;
  for (std::size_t i = 0; i < lidars.size(); ++i) {
    const std::string key = "lidars[" + std::to_string(i) + "]";
    rig.lidars.push_back(reader.lidar(lidars[i], key));
    if (!names.insert(rig.lidars.back().name).second) reader.fail(key + ".name", "duplicate LiDAR name");
    if (std::abs(rig.lidars.back().model.sweep_period - rig.lidars.front().model.sweep_period) > 1e-12)
      reader.fail(key + ".model.sweep_period", "every LiDAR of a rig must share the sweep period");
  }
  rig.base_frame = root["base"] ? reader.text(root["base"], "base") : rig.lidars.front().name;
  return rig;
}

}  // namespace mlidar::sim
