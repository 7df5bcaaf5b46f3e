// Extrinsics YAML (schema in extrinsics_io.hpp). Every yaml-cpp exception is
// turned into InputError here, so callers only ever see mlidar errors.
#include "mlidar/io/extrinsics_io.hpp"

#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>
#include <Eigen/Eigenvalues>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/text_fields.hpp"
#include "mlidar/io/yaml_fields.hpp"

namespace mlidar::io {
namespace {

constexpr double kQuaternionNormTolerance = 1e-6;
constexpr double kSymmetryTolerance = 1e-9;     // relative to the largest |entry|
constexpr double kEigenvalueTolerance = 1e-12;  // relative to the largest |entry|

void check_keys(const YAML::Node& map, const std::set<std::string>& allowed, const std::string& path, const std::string& source) {
  for (const auto& entry : map) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : "<non-scalar key>";
    if (!allowed.contains(key)) {
      std::string list;
      for (const auto& name : allowed) list += (list.empty() ? "" : ", ") + name;
      throw InputError(source, path.empty() ? key : path + "." + key, "unknown key (expected one of: " + list + ")");
    }
  }
}

std::vector<double> finite_numbers(const YAML::Node& node, std::size_t expected, const std::string& path, const std::string& source) {
  if (!node.IsSequence() || node.size() != expected) {
    throw InputError(source, path,
                     "expected a list of " + std::to_string(expected) + " numbers" +
                         (node.IsSequence() ? ", found " + std::to_string(node.size()) : std::string()));
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < expected; ++i) {
    const std::string element = path + "[" + std::to_string(i) + "]";
    if (!node[i].IsScalar()) throw InputError(source, element, "expected a number");
    const double value = parse_double(node[i].Scalar(), source, element);
    if (!std::isfinite(value)) throw InputError(source, element, "must be finite");
    values.push_back(value);
  }
  return values;
}

Mat6 checked_covariance(const YAML::Node& node, const std::string& path, const std::string& source) {
  const std::vector<double> values = finite_numbers(node, 36, path, source);
  Mat6 covariance;
  for (int k = 0; k < 36; ++k) covariance(k / 6, k % 6) = values[static_cast<std::size_t>(k)];
  const double scale = covariance.cwiseAbs().maxCoeff();
  const double asymmetry = (covariance - covariance.transpose()).cwiseAbs().maxCoeff();
  if (asymmetry > kSymmetryTolerance * scale) {
    throw InputError(source, path, "not symmetric (max |C - C^T| = " + exact_number(asymmetry) + ")");
  }
  const Eigen::SelfAdjointEigenSolver<Mat6> solver(0.5 * (covariance + covariance.transpose()));
  const double smallest = solver.eigenvalues().minCoeff();
  if (smallest < -kEigenvalueTolerance * scale) {
    throw InputError(source, path, "not positive semi-definite (smallest eigenvalue " + exact_number(smallest) + ")");
  }
  return covariance;
}

LidarExtrinsic parse_lidar(const std::string& name, const YAML::Node& node, const std::string& source) {
  const std::string path = "lidars." + name;
  if (!node.IsMap()) throw InputError(source, path, "expected a mapping with translation, quaternion_wxyz[, covariance]");
  check_keys(node, {"translation", "quaternion_wxyz", "covariance"}, path, source);
  for (const char* required : {"translation", "quaternion_wxyz"}) {
    if (!node[required]) throw InputError(source, path + "." + required, "missing");
  }
  const auto t = finite_numbers(node["translation"], 3, path + ".translation", source);
  const auto q = finite_numbers(node["quaternion_wxyz"], 4, path + ".quaternion_wxyz", source);
  const Quat rotation(q[0], q[1], q[2], q[3]);
  if (std::abs(rotation.norm() - 1.0) > kQuaternionNormTolerance) {
    throw InputError(source, path + ".quaternion_wxyz",
                     "norm " + exact_number(rotation.norm()) + " is not 1 (within 1e-6); write a unit quaternion [w, x, y, z]");
  }
  LidarExtrinsic lidar{name, SE3(rotation, Vec3(t[0], t[1], t[2])), std::nullopt};
  if (node["covariance"]) lidar.covariance = checked_covariance(node["covariance"], path + ".covariance", source);
  return lidar;
}

Extrinsics parse_document(const YAML::Node& root, const std::string& source) {
  if (!root.IsMap()) throw InputError(source, "", "expected a YAML mapping with keys base and lidars");
  check_keys(root, {"base", "lidars"}, "", source);
  Extrinsics extrinsics;
  if (root["base"]) {
    if (!root["base"].IsScalar() || root["base"].Scalar().empty()) throw InputError(source, "base", "expected a frame name");
    extrinsics.base = root["base"].Scalar();
  }
  const YAML::Node lidars = root["lidars"];
  if (!lidars) throw InputError(source, "lidars", "missing (list the LiDARs: lidars: {NAME: {translation, quaternion_wxyz}})");
  if (!lidars.IsMap() || lidars.size() == 0) throw InputError(source, "lidars", "expected a non-empty mapping NAME: {...}");
  std::set<std::string> names;
  for (const auto& entry : lidars) {
    if (!entry.first.IsScalar() || entry.first.Scalar().empty())
      throw InputError(source, "lidars", "LiDAR names must be non-empty strings");
    const std::string name = entry.first.Scalar();
    if (!names.insert(name).second) throw InputError(source, "lidars." + name, "duplicate LiDAR name");
    extrinsics.lidars.push_back(parse_lidar(name, entry.second, source));
  }
  return extrinsics;
}

void emit_numbers(YAML::Emitter& out, const std::string& key, const auto& values, const std::string& where) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (double v : values) {
    if (!std::isfinite(v)) throw OutputError("extrinsics: " + where + "." + key + " holds a non-finite value");
    out << exact_number(v);
  }
  out << YAML::EndSeq;
}

}  // namespace

const LidarExtrinsic* Extrinsics::find(const std::string& name) const& {
  for (const auto& lidar : lidars) {
    if (lidar.name == name) return &lidar;
  }
  return nullptr;
}

Extrinsics parse_extrinsics(const std::string& yaml_text, const std::string& source) {
  const YAML::Node root = YamlFields(source, "extrinsics YAML").load(yaml_text);
  try {
    return parse_document(root, source);
  } catch (const YAML::Exception& e) {
    throw InputError(source, "yaml", std::string("not valid YAML: ") + e.what());
  }
}

Extrinsics read_extrinsics(const std::filesystem::path& path) { return parse_extrinsics(read_file_text(path), path.string()); }

std::string format_extrinsics(const Extrinsics& extrinsics) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "base" << YAML::Value << extrinsics.base;
  out << YAML::Key << "lidars" << YAML::Value << YAML::BeginMap;
  for (const auto& lidar : extrinsics.lidars) {
    const std::string where = "lidars." + lidar.name;
    const Vec3& t = lidar.T_base_lidar.translation();
    const Quat& q = lidar.T_base_lidar.rotation();
    out << YAML::Key << lidar.name << YAML::Value << YAML::BeginMap;
    emit_numbers(out, "translation", std::vector<double>{t.x(), t.y(), t.z()}, where);
    emit_numbers(out, "quaternion_wxyz", std::vector<double>{q.w(), q.x(), q.y(), q.z()}, where);
    if (lidar.covariance) {
      const Eigen::Matrix<double, 6, 6, Eigen::RowMajor> row_major = *lidar.covariance;
      emit_numbers(out, "covariance", std::vector<double>(row_major.data(), row_major.data() + 36), where);
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void write_extrinsics(const std::filesystem::path& path, const Extrinsics& extrinsics) {
  const std::string text = format_extrinsics(extrinsics);
  write_atomically(path, [&text](std::ostream& out) { out << text; });
}

}  // namespace mlidar::io
