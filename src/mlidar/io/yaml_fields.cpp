#include "mlidar/io/yaml_fields.hpp"

#include <cmath>
#include <utility>

#include "mlidar/core/error.hpp"

namespace mlidar::io {

YamlFields::YamlFields(std::string source, std::string schema) : source_(std::move(source)), schema_(std::move(schema)) {}

YAML::Node YamlFields::load(const std::string& text) const {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail("(document)", std::string("not valid YAML: ") + e.what());
  }
}

void YamlFields::fail(const std::string& key, const std::string& problem) const {
  throw InputError(source_, key, problem);
}

void YamlFields::only_keys(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const {
  if (!map.IsMap()) fail(key.empty() ? "(document)" : key, "expected a mapping");
  for (const auto& entry : map) {
    const auto name = entry.first.as<std::string>();
    if (!allowed.contains(name)) {
      fail(key.empty() ? name : key + "." + name, "unknown key (check the spelling; see the " + schema_ + " schema)");
    }
  }
}

std::string YamlFields::text(const YAML::Node& node, const std::string& key) const {
  if (!node) fail(key, "missing");
  if (!node.IsScalar()) fail(key, "expected a string");
  return node.as<std::string>();
}

double YamlFields::number(const YAML::Node& node, const std::string& key) const {
  if (!node || !node.IsScalar()) fail(key, "expected a number");
  double value = 0.0;
  if (!YAML::convert<double>::decode(node, value) || !std::isfinite(value)) fail(key, "expected a finite number");
  return value;
}

double YamlFields::number_in(const YAML::Node& node, const std::string& key, double lo, double hi) const {
  const double value = number(node, key);
  if (value < lo || value > hi) fail(key, "expected a value in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return value;
}

std::vector<double> YamlFields::numbers(const YAML::Node& node, const std::string& key, std::size_t count) const {
  if (!node.IsSequence() || node.size() == 0 || (count > 0 && node.size() != count)) {
    fail(key, count > 0 ? "expected a list of " + std::to_string(count) + " numbers" : "expected a non-empty list of numbers");
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < node.size(); ++i) values.push_back(number(node[i], key + "[" + std::to_string(i) + "]"));
  return values;
}

}  // namespace mlidar::io
