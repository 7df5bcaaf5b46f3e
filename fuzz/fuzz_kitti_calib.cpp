// libFuzzer target: KITTI calib and label parsers, and the base-frame detection labels and their objects JSON
// built on them (`mlidar eval detections`), on any text.
#include <cstddef>
#include <cstdint>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/detection_labels.hpp"
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
  try {
    mlidar::io::parse_detection_labels(text, "fuzz_pred.txt", mlidar::io::ScoreRule::kRequired);
  } catch (const mlidar::InputError&) {
  }
  try {
    mlidar::io::parse_labelled_objects(text, "fuzz_labels.json");
  } catch (const mlidar::InputError&) {
  }
  return 0;
}
