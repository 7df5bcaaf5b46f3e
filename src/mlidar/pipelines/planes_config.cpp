#include "mlidar/pipelines/planes_config.hpp"

#include <cmath>
#include <functional>
#include <map>

#include "mlidar/core/error.hpp"
#include "mlidar/io/yaml_fields.hpp"

namespace mlidar::pipelines {
namespace {

constexpr double kMaxCount = 1e9;

/// A whole number in [lo, hi] (InputError naming the key otherwise).
template <typename T>
T whole_number(const io::YamlFields& fields, const YAML::Node& node, const std::string& key, double lo, double hi) {
  const double value = fields.number(node, key);
  if (value != std::floor(value) || value < lo || value > hi)
    fields.fail(key, "expected a whole number in [" + std::to_string(static_cast<long long>(lo)) + ", " +
                         std::to_string(static_cast<long long>(hi)) + "]");
  return static_cast<T>(value);
}

}  // namespace

calib::PlanesConfig parse_planes_config(const std::string& yaml_text, const std::string& source) {
  const io::YamlFields fields(source, "planes config (PlanesConfig in src/mlidar/calib/planes_types.hpp)");
  const YAML::Node root = fields.load(yaml_text);
  calib::PlanesConfig config;
  if (root.IsNull()) return config;
  using Reader = std::function<void(const YAML::Node&, const std::string&)>;
  const auto real = [&](double& out) { return Reader([&](const YAML::Node& v, const std::string& k) { out = fields.number(v, k); }); };
  const auto count = [&](auto& out, double hi = kMaxCount) {
    return Reader(
        [&, hi](const YAML::Node& v, const std::string& k) { out = whole_number<std::decay_t<decltype(out)>>(fields, v, k, 0, hi); });
  };
  const std::map<std::string, Reader> readers = {
      {"inlier_distance", real(config.inlier_distance)},
      {"ransac_iterations", count(config.ransac_iterations)},
      {"max_planes", count(config.max_planes)},
      {"min_plane_points", count(config.min_plane_points)},
      {"min_corner_angle_deg", real(config.min_corner_angle_deg)},
      {"min_any_angle_deg", real(config.min_any_angle_deg)},
      {"corner_max_gap", real(config.corner_max_gap)},
      {"warn_min_inliers", count(config.warn_min_inliers)},
      {"max_points_per_plane", count(config.max_points_per_plane)},
      {"huber_delta", real(config.huber_delta)},
      {"max_iterations", count(config.max_iterations)},
      {"max_rotation_sigma_deg", real(config.max_rotation_sigma_deg)},
      {"seed", count(config.seed, 9007199254740992.0)},  // 2^53: exact in a double
      {"up", Reader([&](const YAML::Node& v, const std::string& k) {
         const auto up = fields.numbers(v, k, 3);
         config.up = Vec3(up[0], up[1], up[2]);
       })},
  };
  std::set<std::string> keys;
  for (const auto& [key, reader] : readers) keys.insert(key);
  fields.only_keys(root, "", keys);
  for (const auto& entry : root) {
    const std::string key = entry.first.Scalar();
    readers.at(key)(entry.second, key);
  }
  if (const auto problem = config.problem()) fields.fail(problem->key, std::string("expected ") + problem->expected);
  return config;
}

}  // namespace mlidar::pipelines
