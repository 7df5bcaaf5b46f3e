// PLY writer: binary little endian, one vertex element holding every column.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/ply.hpp"
#include "mlidar/io/ply_header.hpp"

namespace mlidar::io {
namespace {

// Magnitude of a 64-bit integer element, read exactly (no rounding through double).
std::uint64_t integer_magnitude(const FieldColumn& column, std::size_t point, std::uint32_t element) {
  const std::byte* p = column.data.data() + point * column.stride() + element * sizeof(std::uint64_t);
  if (column.type == ScalarType::kU64) {
    std::uint64_t value;
    std::memcpy(&value, p, sizeof(value));
    return value;
  }
  std::int64_t value;
  std::memcpy(&value, p, sizeof(value));
  return value < 0 ? 0 - static_cast<std::uint64_t>(value) : static_cast<std::uint64_t>(value);
}

// PLY has no 64-bit integer type: such a column is written as float64 when
// every value is an integer of magnitude <= 2^53 (exact in a double).
FieldColumn as_ply_column(const FieldColumn& column, std::size_t num_points) {
  if (column.type != ScalarType::kI64 && column.type != ScalarType::kU64) return column;
  constexpr std::uint64_t kExactLimit = std::uint64_t{1} << 53;
  FieldColumn converted{column.name, ScalarType::kF64, column.count, {}};
  converted.data.resize(num_points * converted.stride());
  for (std::size_t i = 0; i < num_points; ++i) {
    for (std::uint32_t k = 0; k < column.count; ++k) {
      if (integer_magnitude(column, i, k) > kExactLimit) {
        throw OutputError("PLY: column " + column.name +
                          " holds a 64-bit integer beyond 2^53, which PLY cannot store "
                          "exactly (PLY has no 64-bit integer type)");
      }
      const double value = column.value(i, k);
      std::memcpy(converted.data.data() + (i * column.count + k) * sizeof(double), &value, sizeof(double));
    }
  }
  return converted;
}

void check_name(const std::string& name) {
  const bool bad = name.empty() || std::any_of(name.begin(), name.end(), [](char c) {
                     return static_cast<unsigned char>(c) <= ' ' || static_cast<unsigned char>(c) >= 0x7f;
                   });
  if (bad) throw OutputError("PLY: column name '" + name + "' is empty or holds whitespace/non-ASCII characters");
}

std::string header_text(const PlyCloud& cloud, const std::vector<FieldColumn>& columns) {
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  for (std::string comment : cloud.comments) {
    std::replace(comment.begin(), comment.end(), '\n', ' ');
    std::replace(comment.begin(), comment.end(), '\r', ' ');
    header += "comment " + comment + "\n";
  }
  header += "element vertex " + std::to_string(cloud.table.num_points) + "\n";
  for (const auto& column : columns) {
    check_name(column.name);
    const std::string type = ply_detail::ply_type_name(column.type);
    if (column.count == 1) {
      header += "property " + type + " " + column.name + "\n";
      continue;
    }
    for (std::uint32_t k = 0; k < column.count; ++k) {
      header += "property " + type + " " + column.name + "_" + std::to_string(k) + "\n";
    }
  }
  return header + "end_header\n";
}

}  // namespace

std::vector<std::byte> encode_ply(const PlyCloud& cloud) {
  const PointTable& table = cloud.table;
  std::vector<FieldColumn> columns;
  std::size_t row_bytes = 0;
  for (const auto& column : table.fields) {
    if (column.data.size() != table.num_points * column.stride()) {
      throw OutputError("PLY: column " + column.name + " holds " + std::to_string(column.data.size()) +
                        " bytes, expected num_points * stride = " + std::to_string(table.num_points * column.stride()));
    }
    columns.push_back(as_ply_column(column, table.num_points));
    row_bytes += columns.back().stride();
  }
  const std::string header = header_text(cloud, columns);
  std::vector<std::byte> bytes(header.size() + row_bytes * table.num_points);
  std::memcpy(bytes.data(), header.data(), header.size());
  std::byte* out = bytes.data() + header.size();
  for (std::size_t i = 0; i < table.num_points; ++i) {
    for (const auto& column : columns) {
      const std::size_t stride = column.stride();
      std::memcpy(out, column.data.data() + i * stride, stride);
      if constexpr (std::endian::native == std::endian::big) {
        const std::size_t size = scalar_size(column.type);
        for (std::size_t k = 0; k < column.count; ++k) std::reverse(out + k * size, out + (k + 1) * size);
      }
      out += stride;
    }
  }
  return bytes;
}

void write_ply(const std::filesystem::path& path, const PlyCloud& cloud) {
  const std::vector<std::byte> bytes = encode_ply(cloud);
  write_atomically(path, [&bytes](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace mlidar::io
