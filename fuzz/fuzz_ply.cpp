// libFuzzer target: parse_ply must throw InputError or succeed on any bytes,
// and whatever it reads must encode and read back.
#include <cstddef>
#include <cstdint>
#include <span>

#include "mlidar/core/error.hpp"
#include "mlidar/io/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  try {
    const mlidar::io::PlyCloud cloud = mlidar::io::parse_ply(bytes, "fuzz.ply");
    const auto encoded = mlidar::io::encode_ply(cloud);
    const mlidar::io::PlyCloud back = mlidar::io::parse_ply(encoded, "fuzz-reencoded.ply");
    if (back.table.num_points != cloud.table.num_points) __builtin_trap();
  } catch (const mlidar::InputError&) {
  } catch (const mlidar::OutputError&) {  // e.g. a column name the writer refuses
  }
  return 0;
}
