// libFuzzer target: the MCAP reader and the CDR message decoders (bag_fuzz.hpp).
#include "bag_fuzz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = mlidar::fuzz::scratch() / "fuzz.mcap";
  mlidar::fuzz::exercise(data, size, file, [&] { return mlidar::io::open_mcap(file); });
  return 0;
}
