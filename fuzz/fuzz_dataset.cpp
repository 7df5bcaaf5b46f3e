// libFuzzer target: dataset.yaml and times.txt, the first byte picks the
// reader. Every problem must be InputError (yaml-cpp's exceptions included);
// a parsed dataset.yaml must format and parse again to the same text.
#include <cstddef>
#include <cstdint>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/dataset.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] % 2 == 0) {
      const mlidar::io::Dataset dataset = mlidar::io::parse_dataset_yaml(text, "fuzz.yaml");
      const std::string formatted = mlidar::io::format_dataset_yaml(dataset);
      if (mlidar::io::format_dataset_yaml(mlidar::io::parse_dataset_yaml(formatted, "formatted.yaml")) != formatted) __builtin_trap();
    } else {
      mlidar::io::parse_times(text, "times.txt");
    }
  } catch (const mlidar::InputError&) {
  }
  return 0;
}
