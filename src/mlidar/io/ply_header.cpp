#include "mlidar/io/ply_header.hpp"

#include <charconv>
#include <system_error>

#include "mlidar/core/error.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io::ply_detail {
namespace {

struct TypeSpelling {
  const char* name;
  ScalarType type;
};

constexpr TypeSpelling kTypeSpellings[] = {
    {"char", ScalarType::kI8},   {"int8", ScalarType::kI8},     {"uchar", ScalarType::kU8},   {"uint8", ScalarType::kU8},
    {"short", ScalarType::kI16}, {"int16", ScalarType::kI16},   {"ushort", ScalarType::kU16}, {"uint16", ScalarType::kU16},
    {"int", ScalarType::kI32},   {"int32", ScalarType::kI32},   {"uint", ScalarType::kU32},   {"uint32", ScalarType::kU32},
    {"float", ScalarType::kF32}, {"float32", ScalarType::kF32}, {"double", ScalarType::kF64}, {"float64", ScalarType::kF64},
};

constexpr const char* kTypeList = "char uchar short ushort int uint float double (or int8 ... float64)";

// One header line and where the next one starts.
struct HeaderLine {
  std::string_view text;
  std::size_t next = 0;
};

std::optional<HeaderLine> next_line(std::span<const std::byte> bytes, std::size_t start) {
  if (start >= bytes.size()) return std::nullopt;
  const std::string_view all(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::size_t end = all.find('\n', start);
  if (end == std::string_view::npos) return HeaderLine{all.substr(start), bytes.size()};
  std::string_view text = all.substr(start, end - start);
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  return HeaderLine{text, end + 1};
}

ScalarType type_or_throw(std::string_view name, const std::string& source, const std::string& field) {
  if (const auto type = ply_scalar_type(name)) return *type;
  throw InputError(source, field, "unknown property type '" + std::string(name) + "' (expected one of " + kTypeList + ")");
}

PlyEncoding encoding_or_throw(const std::vector<std::string_view>& tokens, const std::string& source, const std::string& field) {
  if (tokens.size() != 3) throw InputError(source, field, "expected 'format <encoding> 1.0'");
  for (const auto encoding : {PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian, PlyEncoding::kBinaryBigEndian}) {
    if (tokens[1] == ply_encoding_name(encoding)) return encoding;
  }
  throw InputError(source, field,
                   "unknown format '" + std::string(tokens[1]) + "' (expected ascii, binary_little_endian or binary_big_endian)");
}

std::uint64_t element_count_or_throw(std::string_view token, const std::string& source, const std::string& field) {
  std::uint64_t count = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), count);
  if (ec != std::errc() || end != token.data() + token.size()) {
    throw InputError(source, field, "element count '" + std::string(token) + "' is not a non-negative integer");
  }
  return count;
}

PlyProperty property_or_throw(const std::vector<std::string_view>& tokens, const std::string& source, const std::string& field) {
  PlyProperty property;
  if (tokens.size() == 5 && tokens[1] == "list") {
    property.is_list = true;
    property.count_type = type_or_throw(tokens[2], source, field);
    if (is_float(property.count_type)) {
      throw InputError(source, field, "a list's count type must be an integer type, not " + std::string(tokens[2]));
    }
    property.type = type_or_throw(tokens[3], source, field);
    property.name = tokens[4];
    return property;
  }
  if (tokens.size() != 3) {
    throw InputError(source, field, "expected 'property <type> <name>' or 'property list <count type> <item type> <name>'");
  }
  property.type = type_or_throw(tokens[1], source, field);
  property.name = tokens[2];
  return property;
}

void check_vertex_element(const PlyHeader& header, const std::string& source) {
  const PlyElement* vertex = nullptr;
  for (const auto& element : header.elements) {
    if (element.name != "vertex") continue;
    if (vertex != nullptr) throw InputError(source, "element vertex", "declared twice (expected one vertex element)");
    vertex = &element;
  }
  if (vertex == nullptr) throw InputError(source, "element vertex", "missing (a point cloud PLY needs a vertex element)");
  bool has_scalar = false;
  for (std::size_t i = 0; i < vertex->properties.size(); ++i) {
    has_scalar = has_scalar || !vertex->properties[i].is_list;
    for (std::size_t j = 0; j < i; ++j) {
      if (vertex->properties[i].name == vertex->properties[j].name) {
        throw InputError(source, "element vertex: property " + vertex->properties[i].name, "declared twice");
      }
    }
  }
  if (!has_scalar) throw InputError(source, "element vertex", "has no scalar property (expected at least x y z)");
}

}  // namespace

std::optional<ScalarType> ply_scalar_type(std::string_view name) {
  for (const auto& spelling : kTypeSpellings) {
    if (name == spelling.name) return spelling.type;
  }
  return std::nullopt;
}

const char* ply_type_name(ScalarType type) {
  for (const auto& spelling : kTypeSpellings) {
    if (spelling.type == type) return spelling.name;  // the classic spelling comes first
  }
  return nullptr;
}

PlyHeader parse_ply_header(std::span<const std::byte> bytes, const std::string& source) {
  auto line = next_line(bytes, 0);
  if (!line || line->text != "ply") {
    throw InputError(source, "header", "missing the 'ply' magic line (not a PLY file?)");
  }
  PlyHeader header;
  bool has_format = false;
  std::size_t number = 1;
  while (true) {
    line = next_line(bytes, line->next);
    ++number;
    if (!line) throw InputError(source, "header", "ends without 'end_header'");
    const std::string field = "header line " + std::to_string(number);
    const auto tokens = split_tokens(line->text);
    if (tokens.empty()) continue;
    const std::string_view keyword = tokens[0];
    if (keyword == "end_header") {
      header.data_offset = line->next;
      break;
    }
    if (keyword == "format") {
      header.encoding = encoding_or_throw(tokens, source, field);
      has_format = true;
    } else if (keyword == "comment") {
      header.comments.emplace_back(trim(line->text.substr(std::min(line->text.size(), line->text.find("comment") + 7))));
    } else if (keyword == "obj_info") {
      continue;
    } else if (keyword == "element") {
      if (tokens.size() != 3) throw InputError(source, field, "expected 'element <name> <count>'");
      header.elements.push_back({std::string(tokens[1]), element_count_or_throw(tokens[2], source, field), {}});
    } else if (keyword == "property") {
      if (header.elements.empty()) throw InputError(source, field, "property before any element (declare 'element' first)");
      header.elements.back().properties.push_back(property_or_throw(tokens, source, field));
    } else {
      throw InputError(source, field, "unknown header keyword '" + std::string(keyword) + "'");
    }
  }
  if (!has_format) throw InputError(source, "header", "missing the 'format' line");
  check_vertex_element(header, source);
  return header;
}

}  // namespace mlidar::io::ply_detail
