// PCD v0.7 writer: header, then packed records (binary), an LZF block of
// columns (binary_compressed, padding fields left out as PCL does) or text rows.
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <stdexcept>

#include <liblzf/lzf.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/pcd_detail.hpp"

namespace mlidar::io {
namespace {

struct Dimensions {
  std::uint32_t width = 0;
  std::uint32_t height = 1;
};

// A table that cannot be written is a programmer error: say which column is wrong.
Dimensions check_writable(const PointTable& table) {
  if (table.fields.empty()) throw std::invalid_argument("encode_pcd: the point table has no fields");
  std::set<std::string> names;
  for (const FieldColumn& column : table.fields) {
    if (!pcd_detail::is_valid_field_name(column.name)) {
      throw std::invalid_argument("encode_pcd: field name '" + column.name + "' is empty or has spaces or control characters");
    }
    if (column.name != pcd_detail::kPaddingName && !names.insert(column.name).second) {
      throw std::invalid_argument("encode_pcd: field name '" + column.name + "' repeats (only padding _ may)");
    }
    if (column.count == 0) throw std::invalid_argument("encode_pcd: field '" + column.name + "' has count 0");
    if (column.data.size() != table.num_points * column.stride()) {
      throw std::invalid_argument("encode_pcd: field '" + column.name + "' holds " + std::to_string(column.data.size()) +
                                  " bytes, expected num_points x stride = " + std::to_string(table.num_points * column.stride()));
    }
  }
  if (table.num_points > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("encode_pcd: more than 2^32 - 1 points do not fit PCD's WIDTH");
  }
  if (table.height > 1) {
    if (std::uint64_t{table.width} * table.height != table.num_points) {
      throw std::invalid_argument("encode_pcd: organised table of width x height = " + std::to_string(table.width) + " x " +
                                  std::to_string(table.height) + " holds " + std::to_string(table.num_points) + " points");
    }
    return {table.width, table.height};
  }
  return {static_cast<std::uint32_t>(table.num_points), 1};
}

void append_double(std::string& out, double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), result.ptr);
}

const char* type_letter(ScalarType type) {
  if (is_float(type)) return "F";
  switch (type) {
    case ScalarType::kI8:
    case ScalarType::kI16:
    case ScalarType::kI32:
    case ScalarType::kI64:
      return "I";
    default:
      return "U";
  }
}

// The header text, ending with the DATA line, for a validated cloud.
std::string format_header(const PcdCloud& cloud, std::uint32_t width, std::uint32_t height) {
  std::string names = "FIELDS", sizes = "\nSIZE", types = "\nTYPE", counts = "\nCOUNT";
  for (const FieldColumn& column : cloud.table.fields) {
    (names += ' ') += column.name;
    (sizes += ' ') += std::to_string(scalar_size(column.type));
    (types += ' ') += type_letter(column.type);
    (counts += ' ') += std::to_string(column.count);
  }
  std::string out = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
  out.append(names).append(sizes).append(types).append(counts);
  out.append("\nWIDTH ").append(std::to_string(width));
  out.append("\nHEIGHT ").append(std::to_string(height));
  out.append("\nVIEWPOINT");
  for (double value : cloud.viewpoint) {
    out += ' ';
    append_double(out, value);
  }
  out.append("\nPOINTS ").append(std::to_string(cloud.table.num_points));
  out.append("\nDATA ").append(pcd_encoding_name(cloud.encoding)).append("\n");
  return out;
}

void append_binary_body(const PointTable& table, std::vector<std::byte>& out) {
  std::size_t record_size = 0;
  for (const FieldColumn& column : table.fields) record_size += column.stride();
  const std::size_t start = out.size();
  out.resize(start + table.num_points * record_size);
  std::size_t offset = 0;
  for (const FieldColumn& column : table.fields) {
    pcd_detail::strided_copy(column.data.data(), column.stride(), out.data() + start + offset, record_size, column.stride(),
                             table.num_points);
    offset += column.stride();
  }
}

void append_compressed_body(const PointTable& table, std::vector<std::byte>& out) {
  std::vector<std::byte> columns;
  for (const FieldColumn& column : table.fields) {
    if (column.name != pcd_detail::kPaddingName) columns.insert(columns.end(), column.data.begin(), column.data.end());
  }
  if (columns.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw OutputError("binary_compressed PCD holds at most 4 GiB of point data (write DATA binary instead)");
  }
  // liblzf: the output is under 104% of the input; leave room for tiny inputs too.
  const std::size_t capacity = columns.size() + columns.size() / 16 + 64;
  const std::size_t start = out.size();
  out.resize(start + 8 + capacity);
  std::uint32_t compressed = 0;
  if (!columns.empty()) {
    compressed = lzf_compress(columns.data(), static_cast<unsigned int>(columns.size()), out.data() + start + 8,
                              static_cast<unsigned int>(capacity));
    if (compressed == 0) throw OutputError("LZF compression failed (output buffer too small)");
  }
  const auto uncompressed = static_cast<std::uint32_t>(columns.size());
  std::memcpy(out.data() + start, &compressed, 4);
  std::memcpy(out.data() + start + 4, &uncompressed, 4);
  out.resize(start + 8 + compressed);
}

}  // namespace

PcdEncoding pcd_encoding_from_name(const std::string& name) {
  if (name == "binary") return PcdEncoding::kBinary;
  if (name == "binary_compressed") return PcdEncoding::kBinaryCompressed;
  if (name == "ascii") return PcdEncoding::kAscii;
  throw UsageError("unknown PCD encoding '" + name + "' (use binary, binary_compressed or ascii)");
}

const char* pcd_encoding_name(PcdEncoding encoding) {
  switch (encoding) {
    case PcdEncoding::kAscii:
      return "ascii";
    case PcdEncoding::kBinary:
      return "binary";
    case PcdEncoding::kBinaryCompressed:
      return "binary_compressed";
  }
  return "?";
}

std::vector<std::byte> encode_pcd(const PcdCloud& cloud) {
  const Dimensions dims = check_writable(cloud.table);
  for (double value : cloud.viewpoint) {
    if (!std::isfinite(value)) throw std::invalid_argument("encode_pcd: the viewpoint holds a non-finite value");
  }
  const std::string header = format_header(cloud, dims.width, dims.height);
  std::vector<std::byte> out;
  const auto* header_bytes = reinterpret_cast<const std::byte*>(header.data());
  out.insert(out.end(), header_bytes, header_bytes + header.size());
  switch (cloud.encoding) {
    case PcdEncoding::kAscii:
      pcd_detail::append_ascii_body(cloud.table, out);
      break;
    case PcdEncoding::kBinary:
      append_binary_body(cloud.table, out);
      break;
    case PcdEncoding::kBinaryCompressed:
      append_compressed_body(cloud.table, out);
      break;
  }
  return out;
}

void write_pcd(const std::filesystem::path& path, const PcdCloud& cloud) {
  const std::vector<std::byte> bytes = encode_pcd(cloud);
  write_atomically(path, [&bytes](std::ostream& stream) {
    stream.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace mlidar::io
