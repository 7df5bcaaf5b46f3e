#pragma once
// Shared by the bag fuzz targets: the input becomes a file, the reader visits
// every message, reads it again by reference and decodes the PointCloud2 and
// TFMessage ones. Every problem must be InputError; a message read again must
// equal the visited one.
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/bag_reader.hpp"

namespace mlidar::fuzz {

/// A per-process scratch folder.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("mlidar_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline void exercise(const std::uint8_t* data, std::size_t size, const std::filesystem::path& file,
                     const std::function<std::unique_ptr<io::BagReader>()>& open) {
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    const auto bag = open();
    bag->for_each({}, [&](const io::BagMessage& m) {
      const io::BagTopic& topic = bag->topics()[m.topic];
      const std::vector<std::byte> again = bag->read(m.where);
      if (again.size() != m.data.size() || !std::equal(again.begin(), again.end(), m.data.begin())) __builtin_trap();
      try {
        if (topic.type.find("PointCloud2") != std::string::npos) io::decode_pointcloud2(m.data, topic.encoding, "fuzz");
        if (topic.type.find("TFMessage") != std::string::npos) io::decode_tf_message(m.data, topic.encoding, "fuzz");
      } catch (const InputError&) {
      }
    });
  } catch (const InputError&) {
  }
}

}  // namespace mlidar::fuzz
