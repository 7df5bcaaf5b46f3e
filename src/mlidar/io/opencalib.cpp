#include "mlidar/io/opencalib.hpp"

#include <numbers>

#include <nlohmann/json.hpp>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/rigid_check.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {
namespace {

// OpenCalib's JSON files hold approximate rotations (the shipped
// p64-to-qt-extrinsic.json is 0.021 off orthonormal, det 0.969): they are
// accepted up to this error and projected onto the nearest rotation.
constexpr double kJsonOrthonormalityTolerance = 0.05;

constexpr std::string_view kDeviceKey = "device_id:";
constexpr std::string_view kPoseKey = "(Roll,Pitch,Yaw,tx,ty,tz):";

// R = Rz(yaw) Ry(pitch) Rx(roll), angles in degrees.
SE3 pose_from_rpy_degrees(const std::vector<double>& v) { return {quat_from_rpy_deg(Vec3(v[0], v[1], v[2])), Vec3(v[3], v[4], v[5])}; }

std::string device_name(long long id, const std::vector<std::string>& names, const std::string& source, const std::string& field) {
  if (names.empty()) return "device_" + std::to_string(id);
  if (id < 0 || static_cast<std::size_t>(id) >= names.size()) {
    throw InputError(source, field, "device_id " + std::to_string(id) + " has no name (" + std::to_string(names.size()) + " names given)");
  }
  return names[static_cast<std::size_t>(id)];
}

}  // namespace

std::map<int, std::filesystem::path> parse_opencalib_cloud_paths(const std::string& text, const std::string& source,
                                                                 const std::filesystem::path& directory) {
  constexpr std::string_view kPathKey = "path:";
  std::map<int, std::filesystem::path> clouds;
  int id = -1;  // the device awaiting its path line, -1: none
  for (const auto& line : split_lines(text)) {
    const std::string_view content = trim(line.text);
    if (content.empty()) continue;
    const std::string field = line_field(line.number);
    if (content.starts_with(kDeviceKey)) {
      if (id >= 0) throw InputError(source, field, "device_id without a 'path:' line before it");
      const long long value = parse_integer(trim(content.substr(kDeviceKey.size())), source, field + " (device_id)");
      if (value < 0 || value > 1'000'000) throw InputError(source, field, "device_id must be in [0, 1000000]");
      if (clouds.contains(static_cast<int>(value)))
        throw InputError(source, field, "device_id " + std::to_string(value) + " appears twice");
      id = static_cast<int>(value);
    } else if (content.starts_with(kPathKey)) {
      if (id < 0) throw InputError(source, field, "path line without a device_id line before it");
      const std::filesystem::path file = std::filesystem::path(std::string(trim(content.substr(kPathKey.size())))).filename();
      if (file.empty() || file == "." || file == "..") throw InputError(source, field, "the path must end in a cloud file name");
      clouds[id] = directory / file;
      id = -1;
    } else {
      throw InputError(source, field, "expected 'device_id: N' or 'path: FILE'");
    }
  }
  if (id >= 0) throw InputError(source, "device_id " + std::to_string(id), "has no path line");
  return clouds;
}

std::map<int, std::filesystem::path> read_opencalib_cloud_paths(const std::filesystem::path& path) {
  return parse_opencalib_cloud_paths(read_file_text(path), path.string(), path.parent_path());
}

Extrinsics parse_opencalib_initial_extrinsics(const std::string& text, const std::string& source, const std::vector<std::string>& names) {
  Extrinsics extrinsics;
  std::vector<long long> ids;
  bool awaiting_pose = false;
  for (const auto& line : split_lines(text)) {
    const std::string_view content = trim(line.text);
    if (content.empty()) continue;
    const std::string field = line_field(line.number);
    if (content.starts_with(kDeviceKey)) {
      if (awaiting_pose) throw InputError(source, field, "device_id without a (Roll,Pitch,Yaw,tx,ty,tz) line before it");
      const long long id = parse_integer(trim(content.substr(kDeviceKey.size())), source, field + " (device_id)");
      if (id < 0) throw InputError(source, field, "device_id must be >= 0");
      if (std::find(ids.begin(), ids.end(), id) != ids.end())
        throw InputError(source, field, "device_id " + std::to_string(id) + " appears twice");
      ids.push_back(id);
      awaiting_pose = true;
    } else if (content.starts_with(kPoseKey)) {
      if (!awaiting_pose) throw InputError(source, field, "pose line without a device_id line before it");
      const auto tokens = split_tokens(content.substr(kPoseKey.size()));
      if (tokens.size() != 6) throw InputError(source, field, "expected 6 numbers (roll pitch yaw in degrees, tx ty tz in metres)");
      std::vector<double> values;
      for (const auto token : tokens) values.push_back(parse_finite(token, source, field));
      extrinsics.lidars.push_back({device_name(ids.back(), names, source, field), pose_from_rpy_degrees(values), std::nullopt});
      awaiting_pose = false;
    } else {
      throw InputError(source, field, "expected 'device_id: N' or '(Roll,Pitch,Yaw,tx,ty,tz): 6 numbers'");
    }
  }
  if (awaiting_pose) throw InputError(source, "device_id " + std::to_string(ids.back()), "has no pose line");
  const auto reference = std::find(ids.begin(), ids.end(), 0LL);
  if (reference == ids.end()) throw InputError(source, "device_id 0", "missing (device 0 is the reference frame)");
  extrinsics.base = extrinsics.lidars[static_cast<std::size_t>(reference - ids.begin())].name;
  return extrinsics;
}

Extrinsics read_opencalib_initial_extrinsics(const std::filesystem::path& path, const std::vector<std::string>& names) {
  return parse_opencalib_initial_extrinsics(read_file_text(path), path.string(), names);
}

namespace {

using Json = nlohmann::json;

const Json& member(const Json& object, const char* key, const std::string& path, const std::string& source) {
  if (!object.is_object() || !object.contains(key)) throw InputError(source, path + "." + key, "missing");
  return object.at(key);
}

std::string string_member(const Json& object, const char* key, const std::string& path, const std::string& source) {
  const Json& value = member(object, key, path, source);
  if (!value.is_string() || value.get<std::string>().empty()) throw InputError(source, path + "." + key, "expected a non-empty string");
  return value.get<std::string>();
}

Mat4 matrix_member(const Json& entry, const std::string& path, const std::string& source) {
  const std::string data_path = path + ".param.sensor_calib.data";
  const Json& data = member(member(member(entry, "param", path, source), "sensor_calib", path + ".param", source), "data",
                            path + ".param.sensor_calib", source);
  if (!data.is_array() || data.size() != 4) throw InputError(source, data_path, "expected 4 rows of 4 numbers");
  Mat4 m;
  for (std::size_t r = 0; r < 4; ++r) {
    if (!data[r].is_array() || data[r].size() != 4) throw InputError(source, data_path, "expected 4 rows of 4 numbers");
    for (std::size_t c = 0; c < 4; ++c) {
      if (!data[r][c].is_number()) throw InputError(source, data_path, "expected numbers");
      m(static_cast<int>(r), static_cast<int>(c)) = data[r][c].get<double>();
    }
  }
  if (!m.allFinite() || !m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1))) {
    throw InputError(source, data_path, "expected finite numbers and a bottom row 0 0 0 1");
  }
  return m;
}

Extrinsics extrinsics_from_json(const Json& root, const std::string& source) {
  if (!root.is_object() || root.empty()) throw InputError(source, "", "expected a JSON object of extrinsic entries");
  Extrinsics extrinsics;
  extrinsics.base.clear();
  for (const auto& [key, entry] : root.items()) {
    const std::string target = string_member(entry, "target_sensor_name", key, source);
    if (extrinsics.base.empty()) {
      extrinsics.base = target;
      extrinsics.lidars.push_back({target, SE3::identity(), std::nullopt});
    } else if (target != extrinsics.base) {
      throw InputError(source, key + ".target_sensor_name", "'" + target + "' differs from the first entry's '" + extrinsics.base + "'");
    }
    const std::string sensor = string_member(entry, "sensor_name", key, source);
    if (extrinsics.find(sensor) != nullptr) throw InputError(source, key + ".sensor_name", "'" + sensor + "' appears twice");
    const SE3 T_target_sensor = checked_rigid(matrix_member(entry, key, source), source, key, kJsonOrthonormalityTolerance);
    extrinsics.lidars.push_back({sensor, T_target_sensor, std::nullopt});
  }
  return extrinsics;
}

}  // namespace

Extrinsics parse_opencalib_json(const std::string& text, const std::string& source) {
  try {
    return extrinsics_from_json(Json::parse(text), source);
  } catch (const Json::exception& e) {
    throw InputError(source, "json", std::string("not valid JSON: ") + e.what());
  }
}

Extrinsics read_opencalib_json(const std::filesystem::path& path) { return parse_opencalib_json(read_file_text(path), path.string()); }

}  // namespace mlidar::io
