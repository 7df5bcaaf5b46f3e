// Detection labels in the base frame (conventions in detection_labels.hpp).
#include "mlidar/io/detection_labels.hpp"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {
namespace {

// Columns of a label line (io/kitti.hpp reads the line; this file gives the fields their base-frame meaning).
constexpr std::size_t kHeightColumn = 8;
constexpr std::size_t kScoreColumn = 15;

ObjectClass class_of_line(const KittiObject& object, const std::string& source) {
  const auto found = object_class_from_name(object.type);
  if (!found) {
    throw InputError(source, kitti_label_field(static_cast<std::size_t>(object.line), 0),
                     "unknown class '" + object.type + "' (known: " + known_object_classes() + ")");
  }
  return *found;
}

/// h, w, l after checking each is > 0 (the reader has checked they are finite).
Vec3 positive_sizes(const KittiObject& object, const std::string& source) {
  for (int k = 0; k < 3; ++k) {
    if (!(object.dimensions[k] > 0.0)) {
      throw InputError(source, kitti_label_field(static_cast<std::size_t>(object.line), kHeightColumn + static_cast<std::size_t>(k)),
                       "a box size must be > 0 metres, found " + exact_number(object.dimensions[k]));
    }
  }
  return object.dimensions;
}

LabelledBox labelled_box(const KittiObject& object, const std::string& source, ScoreRule rule) {
  if (rule == ScoreRule::kRequired && !object.score) {
    throw InputError(source, kitti_label_field(static_cast<std::size_t>(object.line), kScoreColumn),
                     "a prediction needs a score as its 16th value, found 15 values");
  }
  LabelledBox labelled;
  labelled.object_class = class_of_line(object, source);
  const Vec3 hwl = positive_sizes(object, source);
  labelled.box = {object.location, hwl[2], hwl[1], hwl[0], object.rotation_y};
  labelled.score = object.score;
  labelled.line = object.line;
  return labelled;
}

/// The base-frame label as a label_2 line: placeholders for the camera fields (KITTI's "unknown" alpha -10).
KittiObject kitti_line(const LabelledBox& labelled) {
  KittiObject object;
  object.type = object_class_name(labelled.object_class);
  object.alpha = -10.0;
  object.bbox = {-1.0, -1.0, -1.0, -1.0};
  object.dimensions = {labelled.box.height, labelled.box.width, labelled.box.length};
  object.location = labelled.box.center_bottom;
  object.rotation_y = labelled.box.yaw;
  object.score = labelled.score;
  return object;
}

/// objects[index].key as a non-negative integer.
int points_total_of(const nlohmann::json& object, std::size_t index, const std::string& source) {
  const std::string field = "objects[" + std::to_string(index) + "].points_total";
  const auto found = object.find("points_total");
  if (found == object.end() || !found->is_number_integer() || found->get<long long>() < 0) {
    throw InputError(source, field, "expected a non-negative integer (LiDAR points on the object)");
  }
  return static_cast<int>(std::min<long long>(found->get<long long>(), 1'000'000'000));
}

ObjectClass class_of(const nlohmann::json& object, std::size_t index, const std::string& source) {
  const std::string field = "objects[" + std::to_string(index) + "].class";
  const auto found = object.find("class");
  if (found == object.end() || !found->is_string()) throw InputError(source, field, "expected a class name string");
  const auto object_class = object_class_from_name(found->get<std::string>());
  if (!object_class) {
    throw InputError(source, field, "unknown class '" + found->get<std::string>() + "' (known: " + known_object_classes() + ")");
  }
  return *object_class;
}

}  // namespace

std::string object_class_name(ObjectClass object_class) {
  switch (object_class) {
    case ObjectClass::kCar:
      return "car";
    case ObjectClass::kPedestrian:
      return "pedestrian";
    case ObjectClass::kCyclist:
      return "cyclist";
  }
  return "car";
}

std::optional<ObjectClass> object_class_from_name(std::string_view name) {
  const std::string wanted = lowercase(name);
  for (ObjectClass object_class : kObjectClasses) {
    if (object_class_name(object_class) == wanted) return object_class;
  }
  return std::nullopt;
}

std::string known_object_classes() {
  std::string names;
  for (ObjectClass object_class : kObjectClasses) names += (names.empty() ? "" : ", ") + object_class_name(object_class);
  return names;
}

std::vector<LabelledBox> parse_detection_labels(std::string_view text, const std::string& source, ScoreRule rule) {
  std::vector<LabelledBox> boxes;
  for (const KittiObject& object : parse_kitti_labels(std::string(text), source)) boxes.push_back(labelled_box(object, source, rule));
  return boxes;
}

std::vector<LabelledBox> read_detection_labels(const std::filesystem::path& path, ScoreRule rule) {
  return parse_detection_labels(read_file_text(path), path.string(), rule);
}

std::string format_detection_labels(std::span<const LabelledBox> boxes, const std::string& destination) {
  std::vector<KittiObject> objects;
  objects.reserve(boxes.size());
  for (const LabelledBox& labelled : boxes) objects.push_back(kitti_line(labelled));
  return format_kitti_labels(objects, destination);
}

void write_detection_labels(const std::filesystem::path& path, std::span<const LabelledBox> boxes) {
  const std::string text = format_detection_labels(boxes, path.string());
  write_atomically(path, [&text](std::ostream& out) { out << text; });
}

std::vector<LabelledObjectInfo> parse_labelled_objects(std::string_view text, const std::string& source) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded()) throw InputError(source, "JSON", "not valid JSON");
  if (!json.is_object() || !json.contains("objects") || !json["objects"].is_array()) {
    throw InputError(source, "objects", "expected an \"objects\" array");
  }
  std::vector<LabelledObjectInfo> objects;
  const nlohmann::json& array = json["objects"];
  for (std::size_t i = 0; i < array.size(); ++i) {
    if (!array[i].is_object()) throw InputError(source, "objects[" + std::to_string(i) + "]", "expected an object");
    objects.push_back({class_of(array[i], i, source), points_total_of(array[i], i, source)});
  }
  return objects;
}

std::vector<LabelledObjectInfo> read_labelled_objects(const std::filesystem::path& path) {
  return parse_labelled_objects(read_file_text(path), path.string());
}

}  // namespace mlidar::io
