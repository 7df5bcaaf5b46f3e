#pragma once
// PLY: ascii, binary_little_endian and binary_big_endian. The `vertex`
// element becomes a PointTable (every scalar property kept, list properties
// and other elements skipped). Writing is binary little endian.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

enum class PlyEncoding : std::uint8_t { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
const char* ply_encoding_name(PlyEncoding encoding);  ///< "ascii", "binary_little_endian", ...

struct PlyCloud {
  PlyEncoding encoding = PlyEncoding::kBinaryLittleEndian;
  std::vector<std::string> comments;
  PointTable table;  ///< the vertex element; COUNT > 1 columns are written as name_0, name_1, ...
};

PlyCloud parse_ply(std::span<const std::byte> bytes, const std::string& source);
PlyCloud read_ply(const std::filesystem::path& path);

/// Binary little endian PLY of every column (covariance, intensity, ... included).
std::vector<std::byte> encode_ply(const PlyCloud& cloud);
void write_ply(const std::filesystem::path& path, const PlyCloud& cloud);

}  // namespace mlidar::io
