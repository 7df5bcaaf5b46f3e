#pragma once
// One entry point for every point-cloud format mlidar reads and writes:
// chooses PCD, PLY or KITTI .bin from the file name and keeps every field the
// target format can hold.
#include <array>
#include <filesystem>
#include <string>

#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

enum class CloudFormat : std::uint8_t { kPcd, kPly, kKittiBin };
const char* cloud_format_name(CloudFormat format);  ///< "pcd", "ply", "kitti-bin"

/// From the extension (.pcd, .ply, .bin; case-insensitive). InputError otherwise.
CloudFormat cloud_format_of(const std::filesystem::path& path);

struct CloudReadOptions {
  bool drop_nan = false;
  /// float32 values per point of a .bin: 4 (KITTI x y z reflectance), 5
  /// (nuScenes x y z intensity ring), or 0 = guess (".pcd.bin" names and sizes
  /// that only divide by 20 bytes are nuScenes, everything else KITTI).
  int bin_floats_per_point = 0;
};

struct CloudFile {
  CloudFormat format = CloudFormat::kPcd;
  std::string encoding;                                  ///< "binary", "ascii", "binary_compressed", "binary_little_endian", ...
  std::array<double, 7> viewpoint{0, 0, 0, 1, 0, 0, 0};  ///< PCD only: tx ty tz qw qx qy qz
  PointTable table;
};

/// The format comes from the extension; for "-" (standard input) and pipes (/dev/fd/N) from the first bytes.
CloudFile read_cloud(const std::filesystem::path& path, const CloudReadOptions& options = {});

struct CloudWriteOptions {
  /// PCD: "binary" (default), "binary_compressed" or "ascii". Others ignore it.
  std::string pcd_encoding = "binary";
};

/// Writes `cloud.table` in the format of `path`'s extension, atomically.
/// PLY drops PCD padding fields ("_"); KITTI .bin keeps x y z and intensity.
void write_cloud(const std::filesystem::path& path, const CloudFile& cloud, const CloudWriteOptions& options = {});

}  // namespace mlidar::io
