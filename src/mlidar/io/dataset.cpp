#include "mlidar/io/dataset.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <regex>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/text_fields.hpp"
#include "mlidar/io/yaml_fields.hpp"

namespace mlidar::io {
namespace {

// The dataset.yaml schema on top of the generic strict accessors.
class Checker : public YamlFields {
 public:
  explicit Checker(std::string source) : YamlFields(std::move(source), "dataset.yaml") {}

  /// A relative path inside the dataset folder.
  std::filesystem::path inner_path(const YAML::Node& node, const std::string& key) const {
    const std::filesystem::path path = text(node, key);
    if (path.empty() || path.is_absolute()) fail(key, "expected a path relative to the dataset folder");
    for (const auto& part : path) {
      if (part == "..") fail(key, "must stay inside the dataset folder (no '..')");
    }
    return path;
  }

  SE3 extrinsic(const YAML::Node& node, const std::string& key) const {
    only_keys(node, key, {"translation", "quaternion_wxyz"});
    if (!node["translation"]) fail(key + ".translation", "missing");
    if (!node["quaternion_wxyz"]) fail(key + ".quaternion_wxyz", "missing");
    const auto t = numbers(node["translation"], key + ".translation", 3);
    const auto q = numbers(node["quaternion_wxyz"], key + ".quaternion_wxyz", 4);
    Quat rotation(q[0], q[1], q[2], q[3]);
    if (std::abs(rotation.norm() - 1.0) > 1e-6) fail(key + ".quaternion_wxyz", "expected a unit quaternion (norm 1 within 1e-6)");
    return SE3(rotation, Vec3(t[0], t[1], t[2]));  // SE3 normalises
  }

  /// One elevation per ring in ring order: ring r is the r-th smallest (slam/range_image.hpp).
  std::vector<double> increasing_angles(const YAML::Node& node, const std::string& key) const {
    std::vector<double> angles = numbers(node, key, 0);
    for (std::size_t i = 1; i < angles.size(); ++i) {
      if (!(angles[i] > angles[i - 1]))
        fail(key + "[" + std::to_string(i) + "]",
             "must be greater than the angle before it (list the rings' elevations in increasing order, "
             "each once; ring r is the r-th lowest beam)");
    }
    return angles;
  }

  DatasetLidar lidar(const YAML::Node& node, const std::string& key) const {
    only_keys(node, key,
              {"name", "model", "scans", "vertical_angles_deg", "horizontal_resolution_deg", "min_range", "max_range", "range_noise_sigma",
               "initial_extrinsic", "time_unit"});
    DatasetLidar lidar;
    lidar.name = text(node["name"], key + ".name");
    if (!std::regex_match(lidar.name, std::regex("[A-Za-z0-9_-]+"))) fail(key + ".name", "use letters, digits, '_' or '-'");
    lidar.model.name = text(node["model"], key + ".model");
    lidar.scans = inner_path(node["scans"], key + ".scans");
    if (node["vertical_angles_deg"])
      lidar.model.vertical_angles_deg = increasing_angles(node["vertical_angles_deg"], key + ".vertical_angles_deg");
    auto positive = [&](const char* field, double& out) {
      if (!node[field]) return;
      out = number(node[field], key + "." + field);
      if (out <= 0.0) fail(key + "." + field, "expected a positive number");
    };
    positive("horizontal_resolution_deg", lidar.model.horizontal_resolution_deg);
    positive("min_range", lidar.model.min_range);
    positive("max_range", lidar.model.max_range);
    if (!(lidar.model.max_range > lidar.model.min_range))
      fail(key + ".max_range", "must be greater than min_range (" + std::to_string(lidar.model.min_range) + " m)");
    positive("range_noise_sigma", lidar.model.range_noise_sigma);
    if (node["time_unit"]) {
      const auto unit = parse_time_unit(text(node["time_unit"], key + ".time_unit"));
      if (!unit) fail(key + ".time_unit", "expected s, ms, us, ns or auto");
      lidar.time_unit = *unit;
    }
    if (node["initial_extrinsic"]) lidar.initial_extrinsic = extrinsic(node["initial_extrinsic"], key + ".initial_extrinsic");
    return lidar;
  }
};

const DatasetLidar* find_lidar(const Dataset& dataset, const std::string& name) {
  for (const auto& lidar : dataset.lidars)
    if (lidar.name == name) return &lidar;
  return nullptr;
}

/// The base frame is a LiDAR (its extrinsic, if given, is identity) or a frame that reference_lidar places.
void check_base(const Checker& check, const YAML::Node& root, Dataset& dataset) {
  if (root["reference_lidar"]) dataset.reference_lidar = check.text(root["reference_lidar"], "reference_lidar");
  if (const DatasetLidar* base = find_lidar(dataset, dataset.base)) {
    if (!dataset.reference_lidar.empty() && dataset.reference_lidar != dataset.base)
      check.fail("reference_lidar",
                 "is for a base frame that is no LiDAR; the base LiDAR " + dataset.base + " places the frame (remove it)");
    dataset.reference_lidar.clear();
    if (base->initial_extrinsic && !base->initial_extrinsic->log().isZero(1e-9))
      check.fail("base", "the base LiDAR " + dataset.base + " defines the base frame: its initial_extrinsic must be the identity");
    return;
  }
  std::string listed;
  for (const auto& lidar : dataset.lidars) listed += (listed.empty() ? "" : ", ") + lidar.name;
  if (dataset.reference_lidar.empty())
    check.fail("base", "names no LiDAR of lidars (" + listed +
                           "); name the base LiDAR, or, for a frame that is no LiDAR (the vehicle's), "
                           "add reference_lidar: the LiDAR whose initial_extrinsic places it");
  const DatasetLidar* reference = find_lidar(dataset, dataset.reference_lidar);
  if (reference == nullptr) check.fail("reference_lidar", "names no LiDAR of lidars (" + listed + ")");
  if (!reference->initial_extrinsic)
    check.fail("reference_lidar",
               "the LiDAR " + reference->name + " needs its initial_extrinsic: it places the base frame " + dataset.base);
}

void emit_numbers(YAML::Emitter& out, std::span<const double> values) {
  out << YAML::Flow << YAML::BeginSeq;
  for (const double v : values) out << exact_number(v);
  out << YAML::EndSeq;
}

}  // namespace

Dataset parse_dataset_yaml(const std::string& text, const std::string& source) {
  const Checker check(source);
  const YAML::Node root = check.load(text);
  check.only_keys(root, "", {"name", "frame_period", "base", "reference_lidar", "times", "lidars", "groundtruth"});
  Dataset dataset;
  dataset.name = check.text(root["name"], "name");
  dataset.frame_period = check.number(root["frame_period"], "frame_period");
  if (dataset.frame_period <= 0.0) check.fail("frame_period", "expected a positive number of seconds");
  if (!root["base"]) check.fail("base", "missing (name the LiDAR whose frame is the base frame, e.g. base: top)");
  dataset.base = check.text(root["base"], "base");
  if (root["times"]) dataset.times = check.inner_path(root["times"], "times");
  const YAML::Node lidars = root["lidars"];
  if (!lidars || !lidars.IsSequence() || lidars.size() == 0) check.fail("lidars", "expected a non-empty list of LiDARs");
  std::set<std::string> names;
  for (std::size_t i = 0; i < lidars.size(); ++i) {
    const std::string key = "lidars[" + std::to_string(i) + "]";
    dataset.lidars.push_back(check.lidar(lidars[i], key));
    if (!names.insert(dataset.lidars.back().name).second) check.fail(key + ".name", "duplicate LiDAR name");
  }
  check_base(check, root, dataset);
  if (const YAML::Node truth = root["groundtruth"]) {
    check.only_keys(truth, "groundtruth", {"trajectory", "extrinsics", "boxes"});
    if (truth["trajectory"]) dataset.groundtruth.trajectory = check.inner_path(truth["trajectory"], "groundtruth.trajectory");
    if (truth["extrinsics"]) dataset.groundtruth.extrinsics = check.inner_path(truth["extrinsics"], "groundtruth.extrinsics");
    if (truth["boxes"]) dataset.groundtruth.boxes = check.inner_path(truth["boxes"], "groundtruth.boxes");
  }
  return dataset;
}

Dataset read_dataset_yaml(const std::filesystem::path& path) {
  const auto file = std::filesystem::is_directory(path) ? path / "dataset.yaml" : path;
  return parse_dataset_yaml(read_file_text(file), file.string());
}

std::string format_dataset_yaml(const Dataset& dataset) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap << YAML::Key << "name" << YAML::Value << dataset.name;
  out << YAML::Key << "frame_period" << YAML::Value << exact_number(dataset.frame_period);
  out << YAML::Key << "base" << YAML::Value << dataset.base;
  if (!dataset.reference_lidar.empty()) out << YAML::Key << "reference_lidar" << YAML::Value << dataset.reference_lidar;
  out << YAML::Key << "times" << YAML::Value << dataset.times.generic_string();
  out << YAML::Key << "lidars" << YAML::Value << YAML::BeginSeq;
  for (const auto& lidar : dataset.lidars) {
    out << YAML::BeginMap << YAML::Key << "name" << YAML::Value << lidar.name;
    out << YAML::Key << "model" << YAML::Value << lidar.model.name;
    out << YAML::Key << "scans" << YAML::Value << lidar.scans.generic_string();
    if (!lidar.model.vertical_angles_deg.empty()) {
      out << YAML::Key << "vertical_angles_deg" << YAML::Value;
      emit_numbers(out, lidar.model.vertical_angles_deg);
    }
    out << YAML::Key << "horizontal_resolution_deg" << YAML::Value << exact_number(lidar.model.horizontal_resolution_deg);
    out << YAML::Key << "min_range" << YAML::Value << exact_number(lidar.model.min_range);
    out << YAML::Key << "max_range" << YAML::Value << exact_number(lidar.model.max_range);
    if (lidar.model.range_noise_sigma > 0.0)
      out << YAML::Key << "range_noise_sigma" << YAML::Value << exact_number(lidar.model.range_noise_sigma);
    if (lidar.time_unit != TimeUnit::kAuto) out << YAML::Key << "time_unit" << YAML::Value << time_unit_name(lidar.time_unit);
    if (lidar.initial_extrinsic) {
      const SE3& T = *lidar.initial_extrinsic;
      const Vec3& t = T.translation();
      const Quat& q = T.rotation();
      out << YAML::Key << "initial_extrinsic" << YAML::Value << YAML::BeginMap << YAML::Key << "translation" << YAML::Value;
      emit_numbers(out, std::vector<double>{t.x(), t.y(), t.z()});
      out << YAML::Key << "quaternion_wxyz" << YAML::Value;
      emit_numbers(out, std::vector<double>{q.w(), q.x(), q.y(), q.z()});
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  const auto& truth = dataset.groundtruth;
  if (truth.trajectory || truth.extrinsics || truth.boxes) {
    out << YAML::Key << "groundtruth" << YAML::Value << YAML::BeginMap;
    if (truth.trajectory) out << YAML::Key << "trajectory" << YAML::Value << truth.trajectory->generic_string();
    if (truth.extrinsics) out << YAML::Key << "extrinsics" << YAML::Value << truth.extrinsics->generic_string();
    if (truth.boxes) out << YAML::Key << "boxes" << YAML::Value << truth.boxes->generic_string();
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string("# mlidar dataset (schema: src/mlidar/io/dataset.hpp)\n") + out.c_str() + "\n";
}

void write_dataset_yaml(const std::filesystem::path& path, const Dataset& dataset) {
  const std::string text = format_dataset_yaml(dataset);
  write_atomically(path, [&](std::ostream& stream) { stream << text; });
}

std::vector<double> parse_times(const std::string& text, const std::string& source) {
  std::vector<double> stamps;
  std::istringstream lines(text);
  std::string line;
  for (std::size_t number = 1; std::getline(lines, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto last = line.find_last_not_of(" \t\r");
    double stamp = 0.0;
    const char* begin = line.data() + first;
    const char* end = line.data() + last + 1;
    const auto [ptr, ec] = std::from_chars(begin, end, stamp);
    const std::string field = "line " + std::to_string(number);
    if (ec != std::errc{} || ptr != end || !std::isfinite(stamp)) throw InputError(source, field, "expected one number (seconds) per line");
    if (!stamps.empty() && stamp <= stamps.back()) throw InputError(source, field, "stamps must increase strictly");
    stamps.push_back(stamp);
  }
  return stamps;
}

std::vector<double> read_times(const std::filesystem::path& path) { return parse_times(read_file_text(path), path.string()); }

void write_times(const std::filesystem::path& path, std::span<const double> stamps) {
  write_atomically(path, [&](std::ostream& stream) {
    char buffer[64];
    for (const double stamp : stamps) {
      std::snprintf(buffer, sizeof(buffer), "%.17g\n", stamp);
      stream << buffer;
    }
  });
}

}  // namespace mlidar::io
