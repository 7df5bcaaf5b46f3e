// libFuzzer target: KITTI calib and label parsers on any text.
#include <cstddef>
#include <cstdint>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/kitti.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    mlidar::io::parse_kitti_calib(text, "fuzz_calib.txt");
  } catch (const mlidar::InputError&) {
  }
  try {
    mlidar::io::parse_kitti_labels(text, "fuzz_label.txt");
  } catch (const mlidar::InputError&) {
  }
  return 0;
}
