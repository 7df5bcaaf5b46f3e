// PLY body decoding: binary (either byte order) and ascii. Every count is
// checked against the bytes that remain before anything is allocated or read.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <limits>
#include <system_error>

#include "mlidar/core/error.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/ply.hpp"
#include "mlidar/io/ply_header.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {
namespace {
using ply_detail::PlyElement;
using ply_detail::PlyHeader;
using ply_detail::PlyProperty;

// Names the value being read, composed only when an error is thrown.
struct Where {
  const PlyElement& element;
  std::uint64_t row;
  const PlyProperty& property;
  std::string str() const { return "element " + element.name + " row " + std::to_string(row) + " property " + property.name; }
};

// Minimum bytes (binary) or tokens (ascii) one row takes: a list takes at least its count.
std::size_t min_row_units(const PlyElement& element, bool binary) {
  std::size_t units = 0;
  for (const auto& p : element.properties) units += binary ? scalar_size(p.is_list ? p.count_type : p.type) : 1;
  return units;
}

// Rejects a count that cannot fit in what remains (overflow-safe: divides instead of multiplying).
void check_count_fits(const PlyElement& element, std::size_t remaining, bool binary, const std::string& source) {
  const std::size_t per_row = min_row_units(element, binary);
  // ascii: n tokens need at least 2n - 1 bytes (one character and one separator each).
  const std::size_t capacity = per_row == 0 ? 0 : binary ? remaining / per_row : (remaining + 1) / (2 * per_row);
  if (per_row != 0 && element.count > capacity) {
    throw InputError(source, "element " + element.name,
                     "promises " + std::to_string(element.count) + " rows but the data holds at most " + std::to_string(capacity) +
                         " (file truncated or count wrong)");
  }
}

// Vertex columns: one per scalar property, -1 for list properties (skipped).
std::vector<int> add_vertex_columns(const PlyElement& vertex, PointTable& table) {
  table.num_points = static_cast<std::size_t>(vertex.count);
  table.width = static_cast<std::uint32_t>(std::min<std::uint64_t>(vertex.count, std::numeric_limits<std::uint32_t>::max()));
  table.height = 1;
  std::vector<int> column_of;
  for (const auto& p : vertex.properties) {
    column_of.push_back(p.is_list ? -1 : static_cast<int>(table.fields.size()));
    if (!p.is_list) table.add_field(p.name, p.type);
  }
  return column_of;
}

// A list count (any integer type, host order) as a signed 64-bit value.
std::int64_t load_count(ScalarType type, const std::byte* raw) {
  const auto load = [raw]<typename T>(T) {
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return static_cast<std::int64_t>(value);
  };
  switch (type) {
    case ScalarType::kI8:
      return load(std::int8_t{});
    case ScalarType::kU8:
      return load(std::uint8_t{});
    case ScalarType::kI16:
      return load(std::int16_t{});
    case ScalarType::kU16:
      return load(std::uint16_t{});
    case ScalarType::kI32:
      return load(std::int32_t{});
    case ScalarType::kU32:
      return load(std::uint32_t{});
    default:
      return -1;  // the header admits only 8-32 bit integer count types
  }
}

class BinaryBody {
 public:
  static constexpr bool kBinary = true;
  BinaryBody(std::span<const std::byte> body, bool swap, const std::string& source) : body_(body), swap_(swap), source_(source) {}

  std::size_t remaining() const { return body_.size() - pos_; }
  std::size_t max_items(ScalarType type) const { return remaining() / scalar_size(type); }

  // Copies one scalar into `out` in host byte order.
  void read_scalar(ScalarType type, std::byte* out, const Where& where) {
    const std::size_t size = scalar_size(type);
    if (size > remaining()) throw InputError(source_, where.str(), "data ends early (file truncated)");
    std::memcpy(out, body_.data() + pos_, size);
    if (swap_) std::reverse(out, out + size);
    pos_ += size;
  }

  void skip_items(ScalarType type, std::size_t count, const Where&) { pos_ += count * scalar_size(type); }

 private:
  std::span<const std::byte> body_;
  std::size_t pos_ = 0;
  bool swap_;
  const std::string& source_;
};

// Values are whitespace-separated tokens; line breaks carry no meaning.
class AsciiBody {
 public:
  static constexpr bool kBinary = false;
  AsciiBody(std::span<const std::byte> body, const std::string& source)
      : text_(reinterpret_cast<const char*>(body.data()), body.size()), source_(source) {}

  std::size_t remaining() const { return text_.size() - pos_; }
  std::size_t max_items(ScalarType) const { return (remaining() + 1) / 2; }

  void read_scalar(ScalarType type, std::byte* out, const Where& where) {
    while (pos_ < text_.size() && is_blank(text_[pos_])) ++pos_;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_blank(text_[pos_])) ++pos_;
    if (pos_ == start) throw InputError(source_, where.str(), "data ends early (fewer values than the header promises)");
    const std::string_view token = text_.substr(start, pos_ - start);
    if (!parse_scalar_token(token, type, out)) {
      throw InputError(source_, where.str(), "'" + std::string(token.substr(0, 40)) + "' is not a valid " + scalar_name(type));
    }
  }

  void skip_items(ScalarType type, std::size_t count, const Where& where) {
    std::byte scratch[8];
    for (std::size_t i = 0; i < count; ++i) read_scalar(type, scratch, where);
  }

 private:
  static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

  std::string_view text_;
  std::size_t pos_ = 0;
  const std::string& source_;
};

template <typename Body>
void skip_list(Body& body, const Where& where, const std::string& source) {
  std::byte raw[8] = {};
  body.read_scalar(where.property.count_type, raw, where);
  const std::int64_t count = load_count(where.property.count_type, raw);
  if (count < 0) throw InputError(source, where.str(), "negative list count " + std::to_string(count));
  if (static_cast<std::uint64_t>(count) > body.max_items(where.property.type)) {
    throw InputError(source, where.str(), "list count " + std::to_string(count) + " runs past the end of the data");
  }
  body.skip_items(where.property.type, static_cast<std::size_t>(count), where);
}

// Reads one element; its scalar properties become columns of `table` when given.
template <typename Body>
void read_element(Body& body, const PlyElement& element, PointTable* table, const std::string& source) {
  if (element.properties.empty()) return;  // rows of nothing take no data, whatever the count
  check_count_fits(element, body.remaining(), Body::kBinary, source);
  const std::vector<int> column_of = table != nullptr ? add_vertex_columns(element, *table) : std::vector<int>{};
  std::byte scratch[8];
  for (std::uint64_t row = 0; row < element.count; ++row) {
    for (std::size_t k = 0; k < element.properties.size(); ++k) {
      const PlyProperty& p = element.properties[k];
      const Where where{element, row, p};
      if (p.is_list) {
        skip_list(body, where, source);
      } else if (table != nullptr) {
        FieldColumn& column = table->fields[static_cast<std::size_t>(column_of[k])];
        body.read_scalar(p.type, column.data.data() + row * column.stride(), where);
      } else {
        body.read_scalar(p.type, scratch, where);
      }
    }
  }
}

template <typename Body>
PointTable read_elements(const PlyHeader& header, Body& body, const std::string& source) {
  PointTable table;
  for (const auto& element : header.elements) {
    read_element(body, element, element.name == "vertex" ? &table : nullptr, source);
  }
  return table;
}

}  // namespace

const char* ply_encoding_name(PlyEncoding encoding) {
  switch (encoding) {
    case PlyEncoding::kAscii:
      return "ascii";
    case PlyEncoding::kBinaryLittleEndian:
      return "binary_little_endian";
    case PlyEncoding::kBinaryBigEndian:
      return "binary_big_endian";
  }
  return "?";
}

PlyCloud parse_ply(std::span<const std::byte> bytes, const std::string& source) {
  const PlyHeader header = ply_detail::parse_ply_header(bytes, source);
  PlyCloud cloud;
  cloud.encoding = header.encoding;
  cloud.comments = header.comments;
  const auto body = bytes.subspan(header.data_offset);
  if (header.encoding == PlyEncoding::kAscii) {
    AsciiBody reader(body, source);
    cloud.table = read_elements(header, reader, source);
  } else {
    const bool file_is_little = header.encoding == PlyEncoding::kBinaryLittleEndian;
    BinaryBody reader(body, file_is_little != (std::endian::native == std::endian::little), source);
    cloud.table = read_elements(header, reader, source);
  }
  return cloud;
}

PlyCloud read_ply(const std::filesystem::path& path) { return parse_ply(read_file_bytes(path), path.string()); }

}  // namespace mlidar::io
