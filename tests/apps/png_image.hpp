#pragma once
// A PNG reader for the tests' browser screenshots: 8-bit RGB or RGBA,
// non-interlaced (what headless Chromium writes), the five row filters of
// the PNG specification (ISO/IEC 15948, sec 9). Returns nullopt for anything else.
#include <zlib.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

namespace mlidar::test {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<std::array<std::uint8_t, 3>> pixels;  ///< row-major
};

namespace png_detail {

inline std::uint32_t big_endian(const std::string& bytes, std::size_t at) {
  return (std::uint32_t{static_cast<std::uint8_t>(bytes[at])} << 24) | (std::uint32_t{static_cast<std::uint8_t>(bytes[at + 1])} << 16) |
         (std::uint32_t{static_cast<std::uint8_t>(bytes[at + 2])} << 8) | std::uint32_t{static_cast<std::uint8_t>(bytes[at + 3])};
}

inline std::uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return static_cast<std::uint8_t>(pa <= pb && pa <= pc ? a : pb <= pc ? b : c);
}

}  // namespace png_detail

inline std::optional<RgbImage> decode_png(const std::string& bytes) {
  using png_detail::big_endian;
  if (bytes.size() < 8 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return std::nullopt;
  RgbImage image;
  int channels = 0;
  std::string compressed;
  for (std::size_t at = 8; at + 8 <= bytes.size();) {
    const std::uint32_t length = big_endian(bytes, at);
    const std::string type = bytes.substr(at + 4, 4);
    if (at + 12 + length > bytes.size()) return std::nullopt;
    if (type == "IHDR") {
      image.width = static_cast<int>(big_endian(bytes, at + 8));
      image.height = static_cast<int>(big_endian(bytes, at + 12));
      const int depth = static_cast<std::uint8_t>(bytes[at + 16]), colour = static_cast<std::uint8_t>(bytes[at + 17]);
      if (depth != 8 || (colour != 2 && colour != 6) || bytes[at + 20] != 0) return std::nullopt;
      channels = colour == 2 ? 3 : 4;
    } else if (type == "IDAT") {
      compressed += bytes.substr(at + 8, length);
    }
    at += 12 + length;
  }
  if (channels == 0 || image.width <= 0 || image.height <= 0) return std::nullopt;
  const std::size_t stride = static_cast<std::size_t>(image.width) * channels;
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(image.height) * (stride + 1));
  uLongf size = raw.size();
  if (uncompress(raw.data(), &size, reinterpret_cast<const Bytef*>(compressed.data()), compressed.size()) != Z_OK || size != raw.size())
    return std::nullopt;
  std::vector<std::uint8_t> previous(stride, 0), row(stride);
  image.pixels.reserve(static_cast<std::size_t>(image.width) * image.height);
  for (int y = 0; y < image.height; ++y) {
    const std::uint8_t* line = raw.data() + static_cast<std::size_t>(y) * (stride + 1);
    const int filter = line[0];
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= static_cast<std::size_t>(channels) ? row[i - channels] : 0, b = previous[i],
                c = i >= static_cast<std::size_t>(channels) ? previous[i - channels] : 0;
      const int predictor = filter == 0 ? 0 : filter == 1 ? a : filter == 2 ? b : filter == 3 ? (a + b) / 2 : png_detail::paeth(a, b, c);
      if (filter > 4) return std::nullopt;
      row[i] = static_cast<std::uint8_t>(line[1 + i] + predictor);
    }
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = row.data() + static_cast<std::size_t>(x) * channels;
      image.pixels.push_back({p[0], p[1], p[2]});
    }
    previous = row;
  }
  return image;
}

}  // namespace mlidar::test
