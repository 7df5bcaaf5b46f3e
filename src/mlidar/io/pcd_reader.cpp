// PCD reader: header, then DATA binary (packed records), binary_compressed
// (LZF block of field-major columns) or ascii, into PointTable columns.
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>

#include <liblzf/lzf.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/pcd_detail.hpp"

namespace mlidar::io {
namespace {

using pcd_detail::PcdHeader;
static_assert(std::endian::native == std::endian::little, "PCD binary data is read as little endian");

// LZF (liblzf lzf_d.c) emits at most 264 bytes per 3-byte back reference, so a
// block of C compressed bytes decodes to at most 88 * C bytes.
constexpr std::uint64_t kLzfMaxExpansion = 88;

void decode_binary_body(std::span<const std::byte> body, const PcdHeader& header, const std::string& source, PointTable& table) {
  const std::uint64_t needed = header.points * header.record_size;  // overflow-checked by the header parser
  if (body.size() < needed) {
    throw InputError(source, "DATA",
                     "binary data holds " + std::to_string(body.size()) + " bytes but POINTS x record size = " + std::to_string(needed) +
                         " (expected that many bytes: file truncated?)");
  }
  table = pcd_detail::make_table(header);
  std::size_t offset = 0;
  for (FieldColumn& column : table.fields) {
    pcd_detail::strided_copy(body.data() + offset, header.record_size, column.data.data(), column.stride(), column.stride(),
                             table.num_points);
    offset += column.stride();
  }
}

std::uint32_t load_u32(const std::byte* bytes) {
  std::uint32_t value = 0;
  std::memcpy(&value, bytes, sizeof(value));
  return value;
}

// binary_compressed: uint32 compressed size, uint32 uncompressed size, LZF block.
// The block holds each field's column in turn. PCL leaves padding fields (_)
// out of the block; both layouts are accepted, told apart by the uncompressed size.
void decode_compressed_body(std::span<const std::byte> body, const PcdHeader& header, const std::string& source, PointTable& table) {
  if (body.size() < 8) {
    throw InputError(source, "DATA",
                     "binary_compressed data is " + std::to_string(body.size()) +
                         " bytes (expected at least the 8-byte compressed/uncompressed size prefix)");
  }
  const std::uint64_t compressed_size = load_u32(body.data());
  const std::uint64_t uncompressed_size = load_u32(body.data() + 4);
  if (compressed_size > body.size() - 8) {
    throw InputError(source, "DATA",
                     "compressed size " + std::to_string(compressed_size) + " exceeds the " + std::to_string(body.size() - 8) +
                         " bytes left in the file (file truncated?)");
  }
  std::uint64_t padding_stride = 0;
  for (const auto& field : header.fields) padding_stride += field.is_padding() ? field.stride() : 0;
  const std::uint64_t full_size = header.points * header.record_size;
  const std::uint64_t unpadded_size = header.points * (header.record_size - padding_stride);
  const bool has_padding_columns = uncompressed_size == full_size;
  if (!has_padding_columns && uncompressed_size != unpadded_size) {
    throw InputError(source, "DATA",
                     "uncompressed size " + std::to_string(uncompressed_size) + " but POINTS x record size = " + std::to_string(full_size) +
                         " (expected them equal)");
  }
  if (uncompressed_size > kLzfMaxExpansion * compressed_size) {
    throw InputError(source, "DATA",
                     "uncompressed size " + std::to_string(uncompressed_size) + " cannot come from " + std::to_string(compressed_size) +
                         " LZF bytes (expected at most 88x expansion)");
  }
  const auto decoded = std::make_unique_for_overwrite<std::byte[]>(uncompressed_size);
  if (uncompressed_size > 0) {
    const unsigned int produced = lzf_decompress(body.data() + 8, static_cast<unsigned int>(compressed_size), decoded.get(),
                                                 static_cast<unsigned int>(uncompressed_size));
    if (produced != uncompressed_size) {
      throw InputError(
          source, "DATA",
          "LZF block is corrupt (decoded " + std::to_string(produced) + " of " + std::to_string(uncompressed_size) + " bytes)");
    }
  }
  table = pcd_detail::make_table(header);
  std::size_t offset = 0;
  for (FieldColumn& column : table.fields) {
    const bool left_out = column.name == pcd_detail::kPaddingName && !has_padding_columns;
    if (left_out || column.data.empty()) continue;  // padding left out stays zero
    std::memcpy(column.data.data(), decoded.get() + offset, column.data.size());
    offset += column.data.size();
  }
}

// Keeps the points whose x, y and z (those present) are finite; the cloud becomes unorganised.
void drop_non_finite_points(PointTable& table) {
  std::vector<char> finite(table.num_points, 1);
  for (const char* name : {"x", "y", "z"}) {
    const FieldColumn* axis = table.find(name);
    if (axis == nullptr) continue;
    const std::vector<double> values = axis->values(table.num_points);
    for (std::size_t i = 0; i < values.size(); ++i) finite[i] = finite[i] != 0 && std::isfinite(values[i]) ? 1 : 0;
  }
  std::vector<std::size_t> kept;
  kept.reserve(table.num_points);
  for (std::size_t i = 0; i < table.num_points; ++i) {
    if (finite[i] != 0) kept.push_back(i);
  }
  table.width = static_cast<std::uint32_t>(kept.size());
  table.height = 1;
  if (kept.size() == table.num_points) return;  // nothing to drop: every column stays as read
  for (FieldColumn& column : table.fields) {
    const std::size_t stride = column.stride();
    for (std::size_t j = 0; j < kept.size(); ++j) {
      std::memmove(column.data.data() + j * stride, column.data.data() + kept[j] * stride, stride);
    }
    column.data.resize(kept.size() * stride);
  }
  table.num_points = kept.size();
}

}  // namespace

PcdCloud parse_pcd(std::span<const std::byte> bytes, const std::string& source, const PcdReadOptions& options) {
  const PcdHeader header = pcd_detail::parse_pcd_header(bytes, source);
  PcdCloud cloud;
  cloud.version = header.version;
  cloud.encoding = header.encoding;
  cloud.viewpoint = header.viewpoint;
  const auto body = bytes.subspan(header.data_offset);
  switch (header.encoding) {
    case PcdEncoding::kAscii:
      pcd_detail::decode_ascii_body(body, header, source, cloud.table);
      break;
    case PcdEncoding::kBinary:
      decode_binary_body(body, header, source, cloud.table);
      break;
    case PcdEncoding::kBinaryCompressed:
      decode_compressed_body(body, header, source, cloud.table);
      break;
  }
  if (options.drop_nan) drop_non_finite_points(cloud.table);
  return cloud;
}

PcdCloud read_pcd(const std::filesystem::path& path, const PcdReadOptions& options) {
  const std::vector<std::byte> bytes = read_file_bytes(path);
  return parse_pcd(bytes, path.string(), options);
}

}  // namespace mlidar::io
