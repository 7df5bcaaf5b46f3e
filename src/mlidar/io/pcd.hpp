#pragma once
// PCD (Point Cloud Library format) v0.5-0.7: DATA ascii, binary and
// binary_compressed (LZF). Every TYPE/SIZE pair (I/U 1,2,4,8; F 4,8),
// COUNT > 1, padding fields named "_", organised clouds and VIEWPOINT.
#include <array>
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

enum class PcdEncoding : std::uint8_t { kAscii, kBinary, kBinaryCompressed };
const char* pcd_encoding_name(PcdEncoding encoding);  ///< "ascii", "binary", "binary_compressed"
/// The inverse of pcd_encoding_name; UsageError (exit 2) for another name.
PcdEncoding pcd_encoding_from_name(const std::string& name);

struct PcdCloud {
  std::string version = "0.7";
  PcdEncoding encoding = PcdEncoding::kBinary;
  /// tx ty tz qw qx qy qz, as in the header's VIEWPOINT line.
  std::array<double, 7> viewpoint{0, 0, 0, 1, 0, 0, 0};
  PointTable table;
};

struct PcdReadOptions {
  /// Drop points whose x, y or z is not finite (the cloud becomes unorganised: height 1).
  bool drop_nan = false;
};

/// Parses a whole PCD file held in memory; `source` names it in errors.
/// Throws InputError naming the source, the header field and the fix.
PcdCloud parse_pcd(std::span<const std::byte> bytes, const std::string& source, const PcdReadOptions& options = {});
PcdCloud read_pcd(const std::filesystem::path& path, const PcdReadOptions& options = {});

/// Serialises to PCD v0.7 (binary or binary_compressed; ascii for debugging).
std::vector<std::byte> encode_pcd(const PcdCloud& cloud);
/// encode_pcd written atomically (temporary file + rename).
void write_pcd(const std::filesystem::path& path, const PcdCloud& cloud);

}  // namespace mlidar::io
