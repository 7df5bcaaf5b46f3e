// libFuzzer target: any bytes must parse or throw InputError, never crash.
#include <cstddef>
#include <cstdint>
#include <span>

#include "mlidar/core/error.hpp"
#include "mlidar/io/pcd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  for (const bool drop_nan : {false, true}) {
    try {
      const mlidar::io::PcdCloud cloud = mlidar::io::parse_pcd(bytes, "fuzz.pcd", {.drop_nan = drop_nan});
      // Whatever parses must encode again.
      if (!drop_nan) (void)mlidar::io::encode_pcd(cloud);
    } catch (const mlidar::InputError&) {
    }
  }
  return 0;
}
