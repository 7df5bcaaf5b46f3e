#pragma once
// Strict reading of YAML documents: every accessor names the key path in its
// error (InputError "FILE: a.b[2]: problem"), and unknown keys are errors.
// Shared by the dataset.yaml and rig YAML readers.
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace mlidar::io {

class YamlFields {
 public:
  /// `source` names the file in errors; `schema` names the documented schema
  /// an unknown key is checked against (e.g. "dataset.yaml").
  YamlFields(std::string source, std::string schema);

  /// Parses `text`; a syntax error fails with key "(document)", a key given
  /// twice in one mapping (anywhere in the document) with its key path.
  YAML::Node load(const std::string& text) const;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;
  /// `map` must be a mapping whose keys all lie in `allowed` ("" is the document root).
  void only_keys(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const;
  std::string text(const YAML::Node& node, const std::string& key) const;
  double number(const YAML::Node& node, const std::string& key) const;  ///< finite
  double number_in(const YAML::Node& node, const std::string& key, double lo, double hi) const;
  /// A non-empty list of finite numbers; of exactly `count` when count > 0.
  std::vector<double> numbers(const YAML::Node& node, const std::string& key, std::size_t count) const;

 private:
  std::string source_;
  std::string schema_;
};

}  // namespace mlidar::io
