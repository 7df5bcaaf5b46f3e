// DATA ascii: one row per point, the fields' values in header order separated
// by spaces or tabs. Integers must parse exactly and fit their type; floats
// accept nan and inf. Values are written in the shortest form that reads back
// to the same bits (std::to_chars), so ascii round-trips exactly.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "mlidar/core/error.hpp"
#include "mlidar/io/pcd_detail.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io::pcd_detail {
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// Next whitespace-separated word of `line` from `cursor`; empty at the end.
std::string_view next_word(std::string_view line, std::size_t& cursor) {
  while (cursor < line.size() && is_blank(line[cursor])) ++cursor;
  const std::size_t start = cursor;
  while (cursor < line.size() && !is_blank(line[cursor])) ++cursor;
  return line.substr(start, cursor - start);
}

class AsciiRowReader {
 public:
  AsciiRowReader(const PcdHeader& header, const std::string& source, PointTable& table) : header_(header), source_(source), table_(table) {}

  void read_row(std::string_view line, std::size_t row) {
    std::size_t cursor = 0;
    std::uint64_t seen = 0;
    for (FieldColumn& column : table_.fields) {
      const std::size_t size = scalar_size(column.type);
      std::byte* out = column.data.data() + row * column.stride();
      for (std::uint32_t e = 0; e < column.count; ++e, ++seen) {
        const std::string_view word = next_word(line, cursor);
        if (word.empty()) fail_count(row, seen);
        if (!parse_scalar_token(word, column.type, out + e * size)) {
          throw InputError(source_, "DATA",
                           "row " + std::to_string(row + 1) + ": " + printable(word) + " for field " + printable(column.name) +
                               " is not a valid " + scalar_name(column.type) +
                               (is_float(column.type) ? "" : " (expected an integer in its range)"));
        }
      }
    }
    if (!next_word(line, cursor).empty()) fail_count(row, seen + 1);
  }

 private:
  [[noreturn]] void fail_count(std::size_t row, std::uint64_t found) const {
    throw InputError(source_, "DATA",
                     "row " + std::to_string(row + 1) + " has " + (found > header_.values_per_point ? "more than " : "") +
                         std::to_string(std::min(found, header_.values_per_point)) + " values (expected " +
                         std::to_string(header_.values_per_point) + " per row, from FIELDS and COUNT)");
  }

  const PcdHeader& header_;
  const std::string& source_;
  PointTable& table_;
};

template <typename T>
void append_number(const std::byte* in, std::vector<std::byte>& out) {
  T value{};
  std::memcpy(&value, in, sizeof(T));
  std::array<char, 64> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  const auto* first = reinterpret_cast<const std::byte*>(buffer.data());
  out.insert(out.end(), first, first + (result.ptr - buffer.data()));
}

void append_value(const std::byte* in, ScalarType type, std::vector<std::byte>& out) {
  switch (type) {
    case ScalarType::kI8:
      return append_number<std::int8_t>(in, out);
    case ScalarType::kU8:
      return append_number<std::uint8_t>(in, out);
    case ScalarType::kI16:
      return append_number<std::int16_t>(in, out);
    case ScalarType::kU16:
      return append_number<std::uint16_t>(in, out);
    case ScalarType::kI32:
      return append_number<std::int32_t>(in, out);
    case ScalarType::kU32:
      return append_number<std::uint32_t>(in, out);
    case ScalarType::kI64:
      return append_number<std::int64_t>(in, out);
    case ScalarType::kU64:
      return append_number<std::uint64_t>(in, out);
    case ScalarType::kF32:
      return append_number<float>(in, out);
    case ScalarType::kF64:
      return append_number<double>(in, out);
  }
}

}  // namespace

void decode_ascii_body(std::span<const std::byte> body, const PcdHeader& header, const std::string& source, PointTable& table) {
  // Every value takes at least one byte: refuse before allocating what the file cannot hold.
  if (header.points * header.values_per_point > body.size()) {
    throw InputError(source, "DATA",
                     "ascii data of " + std::to_string(body.size()) + " bytes cannot hold POINTS = " + std::to_string(header.points) +
                         " rows of " + std::to_string(header.values_per_point) + " values (expected that many rows: file truncated?)");
  }
  table = make_table(header);
  const std::string_view text(reinterpret_cast<const char*>(body.data()), body.size());
  AsciiRowReader reader(header, source, table);
  std::size_t pos = 0;
  std::size_t row = 0;
  while (row < table.num_points) {
    if (pos >= text.size()) {
      throw InputError(source, "DATA",
                       "ascii data ends after " + std::to_string(row) + " rows but POINTS = " + std::to_string(table.num_points) +
                           " (expected one row per point: file truncated?)");
    }
    const std::size_t newline = text.find('\n', pos);
    const std::size_t end = newline == std::string_view::npos ? text.size() : newline;
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    std::size_t cursor = 0;
    if (next_word(line, cursor).empty()) continue;  // blank line
    reader.read_row(line, row++);
  }
}

void append_ascii_body(const PointTable& table, std::vector<std::byte>& out) {
  for (std::size_t i = 0; i < table.num_points; ++i) {
    bool first = true;
    for (const FieldColumn& column : table.fields) {
      const std::size_t size = scalar_size(column.type);
      const std::byte* in = column.data.data() + i * column.stride();
      for (std::uint32_t e = 0; e < column.count; ++e) {
        if (!first) out.push_back(std::byte{' '});
        first = false;
        append_value(in + e * size, column.type, out);
      }
    }
    out.push_back(std::byte{'\n'});
  }
}

}  // namespace mlidar::io::pcd_detail
