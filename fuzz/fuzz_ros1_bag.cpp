// libFuzzer target: the ROS 1 bag reader and the ROS 1 message decoders (bag_fuzz.hpp).
#include "bag_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = mlidar::fuzz::scratch() / "fuzz.bag";
  mlidar::fuzz::exercise(data, size, file, [&] { return mlidar::io::open_ros1_bag(file); });
  return 0;
}
