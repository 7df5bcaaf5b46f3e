// KITTI velodyne .bin scans and label_2 object files (KITTI object
// development kit readme: 15 values per label line, a 16th score for results).
#include "mlidar/io/kitti.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {
namespace {

std::string bin_field_name(int index) {
  constexpr const char* kNames[] = {"x", "y", "z", "intensity", "ring"};
  return index < 5 ? kNames[index] : "field_" + std::to_string(index);
}

float load_le_float(const std::byte* p) {
  std::byte raw[4];
  std::memcpy(raw, p, 4);
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + 4);
  float value;
  std::memcpy(&value, raw, 4);
  return value;
}

void store_le_float(float value, std::ostream& out) {
  char raw[4];
  std::memcpy(raw, &value, 4);
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + 4);
  out.write(raw, 4);
}

}  // namespace

PointTable parse_kitti_bin(std::span<const std::byte> bytes, const std::string& source, int floats_per_point) {
  if (floats_per_point < 3 || floats_per_point > 64) {
    throw InputError(source, "floats_per_point", std::to_string(floats_per_point) + " is not in [3, 64] (KITTI: 4, nuScenes: 5)");
  }
  const std::size_t point_bytes = 4 * static_cast<std::size_t>(floats_per_point);
  if (bytes.size() % point_bytes != 0) {
    throw InputError(source, "file size",
                     std::to_string(bytes.size()) + " bytes is not a multiple of " + std::to_string(point_bytes) + " (" +
                         std::to_string(floats_per_point) + " float32 per point; truncated file or wrong floats_per_point?)");
  }
  PointTable table;
  table.num_points = bytes.size() / point_bytes;
  table.width = static_cast<std::uint32_t>(table.num_points);
  table.height = 1;
  for (int k = 0; k < floats_per_point; ++k) {
    FieldColumn& column = table.add_field(bin_field_name(k), ScalarType::kF32);
    for (std::size_t i = 0; i < table.num_points; ++i) {
      const float value = load_le_float(bytes.data() + i * point_bytes + 4 * static_cast<std::size_t>(k));
      std::memcpy(column.data.data() + 4 * i, &value, 4);
    }
  }
  return table;
}

PointTable read_kitti_bin(const std::filesystem::path& path, int floats_per_point) {
  return parse_kitti_bin(read_file_bytes(path), path.string(), floats_per_point);
}

void write_kitti_bin(const std::filesystem::path& path, const PointTable& table) {
  const FieldColumn* axes[3] = {table.find("x"), table.find("y"), table.find("z")};
  if (std::find(std::begin(axes), std::end(axes), nullptr) != std::end(axes)) {
    throw OutputError(path.string() + ": a KITTI .bin needs fields x, y and z");
  }
  const FieldColumn* intensity = table.find("intensity") != nullptr ? table.find("intensity") : table.find("reflectance");
  write_atomically(path, [&](std::ostream& out) {
    for (std::size_t i = 0; i < table.num_points; ++i) {
      for (const FieldColumn* axis : axes) store_le_float(static_cast<float>(axis->value(i)), out);
      store_le_float(intensity != nullptr ? static_cast<float>(intensity->value(i)) : 0.0f, out);
    }
  });
}

namespace {

constexpr const char* kLabelColumns[] = {"type",       "truncated",   "occluded",   "alpha", "bbox left", "bbox top",
                                         "bbox right", "bbox bottom", "height",     "width", "length",    "location x",
                                         "location y", "location z",  "rotation_y", "score"};

}  // namespace

std::string kitti_label_field(std::size_t line, std::size_t column) {
  return line_field(line) + " column " + std::to_string(column + 1) + " (" + kLabelColumns[column] + ")";
}

namespace {

KittiObject parse_label_line(const std::vector<std::string_view>& tokens, std::size_t line, const std::string& source) {
  if (tokens.size() != 15 && tokens.size() != 16) {
    throw InputError(source, line_field(line),
                     "expected 15 values (type truncated occluded alpha bbox[4] dimensions[3] location[3] rotation_y) "
                     "or 16 with a score, found " +
                         std::to_string(tokens.size()));
  }
  const auto number = [&](std::size_t column) { return parse_finite(tokens[column], source, kitti_label_field(line, column)); };
  KittiObject object;
  object.type = tokens[0];
  object.truncated = number(1);
  const long long occluded = parse_integer(tokens[2], source, kitti_label_field(line, 2));
  if (occluded < -1 || occluded > 3) {
    throw InputError(source, kitti_label_field(line, 2), "expected -1, 0, 1, 2 or 3, found " + std::to_string(occluded));
  }
  object.occluded = static_cast<int>(occluded);
  object.alpha = number(3);
  for (std::size_t k = 0; k < 4; ++k) object.bbox[k] = number(4 + k);
  object.dimensions = {number(8), number(9), number(10)};
  object.location = {number(11), number(12), number(13)};
  object.rotation_y = number(14);
  if (tokens.size() == 16) object.score = number(15);
  object.line = static_cast<int>(line);
  return object;
}

}  // namespace

std::vector<KittiObject> parse_kitti_labels(const std::string& text, const std::string& source) {
  std::vector<KittiObject> objects;
  for (const auto& line : split_lines(text)) {
    const auto tokens = split_tokens(line.text);
    if (!tokens.empty()) objects.push_back(parse_label_line(tokens, line.number, source));
  }
  return objects;
}

std::vector<KittiObject> read_kitti_labels(const std::filesystem::path& path) {
  return parse_kitti_labels(read_file_text(path), path.string());
}

std::string format_kitti_labels(const std::vector<KittiObject>& objects, const std::string& destination) {
  std::string text;
  for (const auto& o : objects) {
    if (o.type.empty() || std::any_of(o.type.begin(), o.type.end(), [](char c) { return c == ' ' || c == '\t' || c == '\n'; })) {
      throw OutputError(destination + ": object type '" + o.type + "' is empty or holds whitespace");
    }
    std::string line = o.type;
    const auto append = [&line](const std::string& value) { line.append(1, ' ').append(value); };
    append(exact_number(o.truncated));
    append(std::to_string(o.occluded));
    append(exact_number(o.alpha));
    for (double v : o.bbox) append(exact_number(v));
    for (int k = 0; k < 3; ++k) append(exact_number(o.dimensions[k]));
    for (int k = 0; k < 3; ++k) append(exact_number(o.location[k]));
    append(exact_number(o.rotation_y));
    if (o.score) append(exact_number(*o.score));
    text.append(line).append(1, '\n');
  }
  return text;
}

void write_kitti_labels(const std::filesystem::path& path, const std::vector<KittiObject>& objects) {
  const std::string text = format_kitti_labels(objects, path.string());
  write_atomically(path, [&text](std::ostream& out) { out << text; });
}

}  // namespace mlidar::io
