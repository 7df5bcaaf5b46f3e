// libFuzzer target: the extrinsics YAML parser must turn every problem,
// yaml-cpp's own exceptions included, into InputError; a parsed file must
// format and parse again.
#include <cstddef>
#include <cstdint>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/extrinsics_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const mlidar::io::Extrinsics extrinsics = mlidar::io::parse_extrinsics(text, "fuzz.yaml");
    const mlidar::io::Extrinsics back = mlidar::io::parse_extrinsics(mlidar::io::format_extrinsics(extrinsics), "fuzz-formatted.yaml");
    if (back.lidars.size() != extrinsics.lidars.size()) __builtin_trap();
  } catch (const mlidar::InputError&) {
  }
  return 0;
}
