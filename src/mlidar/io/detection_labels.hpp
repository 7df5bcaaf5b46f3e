#pragma once
// 3D detection labels in the BASE frame of the vehicle (x forward, y left, z up), in the text layout of KITTI's
// label_2 files (object devkit readme), one object a line:
//
//   class truncated occluded alpha x1 y1 x2 y2 h w l x y z yaw [score]
//
// 15 fields, 16 with a detection's score. Our conventions, NOT KITTI's camera frame:
//   h w l  metres: h vertical, w across, l along the heading (all > 0)
//   x y z  the centre of the box's BOTTOM face in the base frame (thesis 6.6.1: [x, y, z] is the bottom centre)
//   yaw    radians, rotation about base z from base x to the box's length axis, counter-clockwise
//   class  car, pedestrian or cyclist (read case-insensitively, so KITTI's "Car" works; written lowercase)
// The camera fields are read (truncated, alpha and the bbox as numbers, occluded as an integer -1..3) but not kept;
// we write the placeholders truncated 0, occluded 0, alpha -10 and bbox -1 -1 -1 -1. Blank lines are skipped.
//
// labels/NNNNNN.json (written by `mlidar simulate detection`) describes the same objects in the same order; the
// evaluator reads only each object's class and points_total (objects no LiDAR hit are ignored, like KITTI's
// DontCare).
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/core/so3.hpp"

namespace mlidar::io {

enum class ObjectClass : std::uint8_t { kCar, kPedestrian, kCyclist };

inline constexpr std::array<ObjectClass, 3> kObjectClasses = {ObjectClass::kCar, ObjectClass::kPedestrian, ObjectClass::kCyclist};

/// "car", "pedestrian", "cyclist".
std::string object_class_name(ObjectClass object_class);
/// The class named `name`, any letter case; nullopt for other names.
std::optional<ObjectClass> object_class_from_name(std::string_view name);
/// "car, pedestrian, cyclist" for error messages.
std::string known_object_classes();

/// An upright box in the base frame (conventions above).
struct Box3D {
  Vec3 center_bottom = Vec3::Zero();  ///< centre of the bottom face, metres
  double length = 1.0;                ///< along the heading
  double width = 1.0;                 ///< across the heading
  double height = 1.0;                ///< vertical
  double yaw = 0.0;                   ///< radians, base x to the length axis, about base z
};

struct LabelledBox {
  ObjectClass object_class = ObjectClass::kCar;
  Box3D box;
  std::optional<double> score;  ///< detections only
  int line = 0;                 ///< 1-based line in its file (0: not read from a file)
};

/// Whether a file's lines must carry the 16th field (predictions) or may (ground truth: a score there is kept).
enum class ScoreRule : std::uint8_t { kOptional, kRequired };

/// Read by io/kitti.hpp's label reader, then checked: throws InputError(source, "line N column C (NAME)", problem)
/// for a wrong field count, a field that is no finite number, a size <= 0, an unknown class, or a missing score
/// under kRequired.
std::vector<LabelledBox> parse_detection_labels(std::string_view text, const std::string& source, ScoreRule rule);
std::vector<LabelledBox> read_detection_labels(const std::filesystem::path& path, ScoreRule rule);

/// The lines of `boxes` (exact numbers, placeholders for the camera fields, the score when present).
std::string format_detection_labels(std::span<const LabelledBox> boxes, const std::string& destination);
void write_detection_labels(const std::filesystem::path& path, std::span<const LabelledBox> boxes);

/// One object of labels/NNNNNN.json, as far as the evaluation needs it.
struct LabelledObjectInfo {
  ObjectClass object_class = ObjectClass::kCar;
  int points_total = 0;  ///< LiDAR points on the object, all LiDARs together
};

/// The "objects" of a labels/NNNNNN.json in file order. Throws InputError(source, "objects[i].KEY", problem) for
/// text that is no JSON, a missing "objects" array, an object without a known "class" or a non-negative integer
/// "points_total".
std::vector<LabelledObjectInfo> parse_labelled_objects(std::string_view text, const std::string& source);
std::vector<LabelledObjectInfo> read_labelled_objects(const std::filesystem::path& path);

}  // namespace mlidar::io
