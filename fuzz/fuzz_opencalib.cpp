// libFuzzer target: the three OpenCalib readers (initial_extrinsic.txt,
// lidar_cloud_path.txt, *-extrinsic.json) must turn every problem into
// InputError. The first byte picks the reader; the rest is the file.
#include <cstddef>
#include <cstdint>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/opencalib.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0]) {
      case 'i': {
        const mlidar::io::Extrinsics extrinsics = mlidar::io::parse_opencalib_initial_extrinsics(text, "fuzz.txt");
        if (extrinsics.lidars.empty()) __builtin_trap();  // a parsed file names at least the reference
        break;
      }
      case 'p': {
        const auto paths = mlidar::io::parse_opencalib_cloud_paths(text, "fuzz.txt", "scene");
        for (const auto& [id, path] : paths)
          if (id < 0 || path.parent_path() != "scene") __builtin_trap();
        break;
      }
      default:
        (void)mlidar::io::parse_opencalib_json(text, "fuzz.json");
    }
  } catch (const mlidar::InputError&) {
  }
  return 0;
}
