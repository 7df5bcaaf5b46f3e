#pragma once
// A bounds-checked cursor over a byte span for the binary message and bag
// formats: little- or big-endian scalars, length-prefixed strings and byte
// runs, and CDR alignment. Reading past the end is InputError naming the
// source and what was being read, never a crash.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>

#include "mlidar/core/error.hpp"

namespace mlidar::io {

class ByteReader {
 public:
  ByteReader(std::span<const std::byte> bytes, std::string source, bool big_endian = false)
      : bytes_(bytes), source_(std::move(source)), big_endian_(big_endian) {}

  std::size_t position() const { return position_; }
  std::size_t remaining() const { return bytes_.size() - position_; }
  bool at_end() const { return position_ == bytes_.size(); }
  const std::string& source() const { return source_; }
  void set_big_endian(bool big_endian) { big_endian_ = big_endian; }

  /// The next `count` bytes; InputError naming `what` when fewer remain.
  std::span<const std::byte> take(std::size_t count, std::string_view what) {
    if (count > remaining())
      throw InputError(source_, std::string(what),
                       "needs " + std::to_string(count) + " bytes at offset " + std::to_string(position_) + ", " +
                           std::to_string(remaining()) + " remain (truncated, or a length that lies)");
    const auto out = bytes_.subspan(position_, count);
    position_ += count;
    return out;
  }

  template <typename T>
  T scalar(std::string_view what) {
    const auto raw = take(sizeof(T), what);
    T value;
    std::memcpy(&value, raw.data(), sizeof(T));
    if (big_endian_ != (std::endian::native == std::endian::big)) value = swapped(value);
    return value;
  }

  std::uint8_t u8(std::string_view what) { return scalar<std::uint8_t>(what); }
  std::uint32_t u32(std::string_view what) { return scalar<std::uint32_t>(what); }
  std::uint64_t u64(std::string_view what) { return scalar<std::uint64_t>(what); }

  /// CDR: the next scalar of `size` bytes starts at a multiple of `size` from `origin`.
  void align(std::size_t size, std::size_t origin) {
    const std::size_t misalignment = (position_ - origin) % size;
    if (misalignment != 0) take(size - misalignment, "alignment");
  }

  void skip(std::size_t count, std::string_view what) { take(count, what); }
  void seek(std::size_t position) { position_ = position <= bytes_.size() ? position : bytes_.size(); }

  template <typename T>
  static T swapped(T value) {
    std::byte raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }

 private:
  std::span<const std::byte> bytes_;
  std::string source_;
  bool big_endian_ = false;
  std::size_t position_ = 0;
};

}  // namespace mlidar::io
