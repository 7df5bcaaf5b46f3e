#pragma once
// Internal to the PLY reader: the parsed header (Paul Bourke's PLY
// specification: "ply", "format <encoding> 1.0", "comment"/"obj_info",
// "element <name> <count>", "property <type> <name>",
// "property list <count type> <item type> <name>", "end_header").
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/io/ply.hpp"
#include "mlidar/io/point_table.hpp"

namespace mlidar::io::ply_detail {

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::kF32;  ///< the scalar's type, or a list's item type
  bool is_list = false;
  ScalarType count_type = ScalarType::kU8;  ///< lists only: an integer type
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<std::string> comments;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  ///< first byte after the end_header line
};

/// PLY type name (both the classic "uchar" and the sized "uint8" spellings).
std::optional<ScalarType> ply_scalar_type(std::string_view name);
/// The classic spelling written by encode_ply ("char", "uchar", ..., "double").
const char* ply_type_name(ScalarType type);

/// Parses and validates the header; InputError naming `source` and the header line otherwise.
PlyHeader parse_ply_header(std::span<const std::byte> bytes, const std::string& source);

}  // namespace mlidar::io::ply_detail
