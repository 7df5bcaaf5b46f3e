#pragma once
// Internals shared by the PCD reader and writer (not part of the public API).
// Format reference: PCL's "The PCD (Point Cloud Data) file format" page,
// https://pcl.readthedocs.io/projects/tutorials/en/master/pcd_file_format.html
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/io/pcd.hpp"

namespace mlidar::io::pcd_detail {

/// The field name PCL uses for padding bytes; it may repeat.
inline constexpr std::string_view kPaddingName = "_";

struct PcdField {
  std::string name;
  ScalarType type = ScalarType::kF32;
  std::uint32_t count = 1;

  /// Bytes per point (size x count); bounded by the header parser to < 2^35.
  std::uint64_t stride() const { return scalar_size(type) * std::uint64_t{count}; }
  bool is_padding() const { return name == kPaddingName; }
};

struct PcdHeader {
  std::string version;
  std::vector<PcdField> fields;
  std::uint32_t width = 0;
  std::uint32_t height = 1;
  std::uint64_t points = 0;
  std::array<double, 7> viewpoint{0, 0, 0, 1, 0, 0, 0};
  PcdEncoding encoding = PcdEncoding::kBinary;
  std::uint64_t record_size = 0;       ///< bytes of one packed point (all fields)
  std::uint64_t values_per_point = 0;  ///< sum of COUNT (ascii tokens per row)
  std::size_t data_offset = 0;         ///< first byte after the DATA line
};

/// Parses and validates the text header; every size it returns is free of overflow:
/// points * record_size and points * values_per_point fit in 64 bits.
PcdHeader parse_pcd_header(std::span<const std::byte> bytes, const std::string& source);

/// Column-sized, zero-filled table for the header's fields and points.
PointTable make_table(const PcdHeader& header);

/// DATA ascii: one row per point, whitespace-separated values (nan/inf allowed for F).
void decode_ascii_body(std::span<const std::byte> body, const PcdHeader& header, const std::string& source, PointTable& table);
void append_ascii_body(const PointTable& table, std::vector<std::byte>& out);

/// Field names are words: non-empty, no spaces or control characters (UTF-8 is fine).
bool is_valid_field_name(std::string_view name);

/// A printable, length-limited copy of untrusted text for error messages.
std::string printable(std::string_view text);

/// Copies `count` elements of `size` bytes from src (one every src_step bytes)
/// to dst (one every dst_step bytes): packed records <-> columns. Fixed sizes
/// let memcpy become a single load/store (measured ~9x faster than per record).
template <std::size_t kSize>
void strided_copy_fixed(const std::byte* src, std::size_t src_step, std::byte* dst, std::size_t dst_step, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) std::memcpy(dst + i * dst_step, src + i * src_step, kSize);
}

inline void strided_copy(const std::byte* src, std::size_t src_step, std::byte* dst, std::size_t dst_step, std::size_t size,
                         std::size_t count) {
  switch (size) {
    case 1:
      return strided_copy_fixed<1>(src, src_step, dst, dst_step, count);
    case 2:
      return strided_copy_fixed<2>(src, src_step, dst, dst_step, count);
    case 4:
      return strided_copy_fixed<4>(src, src_step, dst, dst_step, count);
    case 8:
      return strided_copy_fixed<8>(src, src_step, dst, dst_step, count);
    case 12:
      return strided_copy_fixed<12>(src, src_step, dst, dst_step, count);
    case 16:
      return strided_copy_fixed<16>(src, src_step, dst, dst_step, count);
    default:
      for (std::size_t i = 0; i < count; ++i) std::memcpy(dst + i * dst_step, src + i * src_step, size);
  }
}

}  // namespace mlidar::io::pcd_detail
