#include "mlidar/io/bag_reader.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>

#include "mlidar/core/error.hpp"

namespace mlidar::io {

const char* bag_format_name(BagFormat format) {
  switch (format) {
    case BagFormat::kRos1:
      return "ros1";
    case BagFormat::kMcap:
      return "mcap";
    case BagFormat::kRosbag2Sqlite:
      return "rosbag2-sqlite3";
  }
  return "?";
}

std::optional<std::size_t> BagReader::find_topic(const std::string& name) const {
  for (std::size_t t = 0; t < topics_.size(); ++t)
    if (topics_[t].name == name) return t;
  return std::nullopt;
}

void BagReader::for_each(const std::vector<bool>& wanted, const std::function<void(const BagMessage&)>& visit) {
  std::vector<std::uint64_t> seen(topics_.size(), 0);
  truncated_.reset();
  pass(wanted, [&](std::size_t topic, std::int64_t log_time_ns, std::span<const std::byte> data, const MessageRef& where) {
    if (topic >= seen.size()) seen.resize(topics_.size(), 0);
    const std::uint64_t index = seen[topic]++;
    if (!wanted.empty() && (topic >= wanted.size() || !wanted[topic])) return;
    visit(BagMessage{topic, index, log_time_ns, data, where});
  });
  if (wanted.empty() || std::all_of(wanted.begin(), wanted.end(), [](bool w) { return w; })) {
    for (std::size_t t = 0; t < topics_.size() && t < seen.size(); ++t) topics_[t].count = seen[t];
  }
}

std::unique_ptr<BagReader> open_bag(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return open_rosbag2(path);
  if (path.extension() == ".db3" || path.filename() == "metadata.yaml") return open_rosbag2(path.parent_path());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "", "no such file (check the path)");
  std::array<char, 13> magic{};
  in.read(magic.data(), magic.size());
  const std::string head(magic.data(), static_cast<std::size_t>(in.gcount()));
  if (head.rfind("#ROSBAG V2.0\n", 0) == 0) return open_ros1_bag(path);
  if (head.size() >= 8 && std::memcmp(head.data(), "\x89MCAP0\r\n", 8) == 0) return open_mcap(path);
  if (head.rfind("#ROSBAG V", 0) == 0) throw InputError(path.string(), "version", "is a ROS bag of another version than 2.0");
  throw InputError(path.string(), "format", "is no ROS 1 bag (#ROSBAG V2.0), MCAP file or rosbag2 folder");
}

}  // namespace mlidar::io
