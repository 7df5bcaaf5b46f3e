// libFuzzer target: a rosbag2 sqlite3 storage file read without metadata.yaml (bag_fuzz.hpp).
#include "bag_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto folder = mlidar::fuzz::scratch() / "rosbag2";
  std::filesystem::create_directories(folder);
  mlidar::fuzz::exercise(data, size, folder / "fuzz_0.db3", [&] { return mlidar::io::open_rosbag2(folder); });
  return 0;
}
