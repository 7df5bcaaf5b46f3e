#include "mlidar/io/yaml_fields.hpp"

#include <cmath>
#include <utility>

#include "mlidar/core/error.hpp"

namespace mlidar::io {

YamlFields::YamlFields(std::string source, std::string schema) : source_(std::move(source)), schema_(std::move(schema)) {}

namespace {

/// The key path of the first key given twice in one mapping of `node`, or empty.
std::string duplicate_key(const YAML::Node& node, const std::string& path) {
  if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      if (std::string found = duplicate_key(node[i], path + "[" + std::to_string(i) + "]"); !found.empty()) return found;
    }
  }
  if (!node.IsMap()) return {};
  std::set<std::string> seen;
  for (const auto& entry : node) {
    const std::string name = entry.first.Scalar();
    const std::string key = path.empty() ? name : path + "." + name;
    if (!seen.insert(name).second) return key;
    if (std::string found = duplicate_key(entry.second, key); !found.empty()) return found;
  }
  return {};
}

}  // namespace

YAML::Node YamlFields::load(const std::string& text) const {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail("(document)", std::string("not valid YAML: ") + e.what());
  }
  if (const std::string key = duplicate_key(root, ""); !key.empty())
    fail(key, "given twice (a YAML key may appear once per mapping; remove one)");
  return root;
}

void YamlFields::fail(const std::string& key, const std::string& problem) const { throw InputError(source_, key, problem); }

void YamlFields::only_keys(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const {
  if (!map.IsMap()) fail(key.empty() ? "(document)" : key, "expected a mapping");
  for (const auto& entry : map) {
    if (!entry.first.IsScalar()) fail(key.empty() ? "(document)" : key, "a key is not a plain name (use name: value)");
    const std::string& name = entry.first.Scalar();
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
