#include "mlidar/io/cloud_file.hpp"

#include <cstring>
#include <span>
#include <string_view>

#include "mlidar/core/error.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/ply.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {

const char* cloud_format_name(CloudFormat format) {
  switch (format) {
    case CloudFormat::kPcd:
      return "pcd";
    case CloudFormat::kPly:
      return "ply";
    case CloudFormat::kKittiBin:
      return "kitti-bin";
  }
  return "?";
}

namespace {

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

int guess_bin_floats(const std::filesystem::path& path, std::size_t size) {
  if (ends_with(lowercase(path.filename().string()), ".pcd.bin")) return 5;
  if (size % 16 != 0 && size % 20 == 0) return 5;
  return 4;
}

bool starts_with(std::span<const std::byte> bytes, std::string_view text) {
  return bytes.size() >= text.size() && std::memcmp(bytes.data(), text.data(), text.size()) == 0;
}

/// A stream's format from its first bytes: "ply" opens a PLY file, a PCD header opens with a comment, VERSION or
/// FIELDS; anything else is read as float32 points (.bin).
CloudFormat sniff_format(std::span<const std::byte> bytes) {
  if (starts_with(bytes, "ply\n") || starts_with(bytes, "ply\r\n")) return CloudFormat::kPly;
  if (starts_with(bytes, "#") || starts_with(bytes, "VERSION") || starts_with(bytes, "FIELDS")) return CloudFormat::kPcd;
  return CloudFormat::kKittiBin;
}

PointTable without_padding(const PointTable& table) {
  PointTable out;
  out.num_points = table.num_points;
  out.width = table.width;
  out.height = table.height;
  for (const auto& field : table.fields) {
    if (field.name != "_") out.fields.push_back(field);
  }
  return out;
}

}  // namespace

CloudFormat cloud_format_of(const std::filesystem::path& path) {
  const std::string extension = lowercase(path.extension().string());
  if (extension == ".pcd") return CloudFormat::kPcd;
  if (extension == ".ply") return CloudFormat::kPly;
  if (extension == ".bin") return CloudFormat::kKittiBin;
  throw InputError(path.string(), "file extension",
                   "unknown point-cloud format '" + extension + "' (mlidar reads .pcd, .ply and KITTI/nuScenes .bin)");
}

CloudFile read_cloud(const std::filesystem::path& path, const CloudReadOptions& options) {
  const bool stream = is_stream_path(path);
  const CloudFormat named = stream ? CloudFormat::kPcd : cloud_format_of(path);  // an unknown extension fails before reading
  const std::vector<std::byte> bytes = read_file_bytes(path);
  const std::string source = path.string();
  CloudFile cloud;
  cloud.format = stream ? sniff_format(bytes) : named;
  switch (cloud.format) {
    case CloudFormat::kPcd: {
      PcdCloud pcd = parse_pcd(bytes, source, PcdReadOptions{options.drop_nan});
      cloud.encoding = pcd_encoding_name(pcd.encoding);
      cloud.viewpoint = pcd.viewpoint;
      cloud.table = std::move(pcd.table);
      break;
    }
    case CloudFormat::kPly: {
      PlyCloud ply = parse_ply(bytes, source);
      cloud.encoding = ply_encoding_name(ply.encoding);
      cloud.table = std::move(ply.table);
      break;
    }
    case CloudFormat::kKittiBin: {
      const int floats = options.bin_floats_per_point > 0 ? options.bin_floats_per_point : guess_bin_floats(path, bytes.size());
      cloud.encoding = floats == 5 ? "float32 x5 (nuScenes)" : "float32 x4 (KITTI)";
      cloud.table = parse_kitti_bin(bytes, source, floats);
      break;
    }
  }
  return cloud;
}

void write_cloud(const std::filesystem::path& path, const CloudFile& cloud, const CloudWriteOptions& options) {
  switch (cloud_format_of(path)) {
    case CloudFormat::kPcd: {
      PcdCloud pcd;
      pcd.encoding = pcd_encoding_from_name(options.pcd_encoding);
      pcd.viewpoint = cloud.viewpoint;
      pcd.table = cloud.table;
      write_pcd(path, pcd);
      return;
    }
    case CloudFormat::kPly: {
      PlyCloud ply;
      ply.table = without_padding(cloud.table);
      write_ply(path, ply);
      return;
    }
    case CloudFormat::kKittiBin:
      write_kitti_bin(path, cloud.table);
      return;
  }
}

}  // namespace mlidar::io
