#pragma once
// Reading robots' recordings without ROS: ROS 1 bags (v2.0), ROS 2 MCAP files
// and ROS 2 rosbag2 folders (sqlite3 .db3, or MCAP storage). A reader lists
// the topics and visits every message in one streaming pass in file order,
// holding one chunk at a time; a message can be read again by its MessageRef
// (the reader keeps the last chunk it decompressed). A bag cut short by a
// crash is read up to its last whole message and truncated() says so; any
// other inconsistency (a length that lies, an unknown compression, a corrupt
// chunk) is InputError naming the file and where.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mlidar/io/mapped_file.hpp"
#include "mlidar/io/ros_messages.hpp"

namespace mlidar::io {

enum class BagFormat : std::uint8_t { kRos1, kMcap, kRosbag2Sqlite };
const char* bag_format_name(BagFormat format);  ///< "ros1", "mcap", "rosbag2-sqlite3"

struct BagTopic {
  std::string name;
  std::string type;  ///< as the bag writes it: sensor_msgs/PointCloud2 (ROS 1) or sensor_msgs/msg/PointCloud2 (ROS 2)
  MessageEncoding encoding = MessageEncoding::kRos1;
  std::uint64_t count = 0;  ///< messages (from the bag's index or summary when it has one, else after a pass)
};

/// Where a message lies, to read it again: the block holding it (a chunk's file offset, a db3 row) and its
/// position there.
struct MessageRef {
  std::uint32_t file = 0;    ///< rosbag2: which storage file
  std::uint64_t block = 0;   ///< ROS 1 / MCAP: the chunk record's offset (or the message record's, outside chunks); db3: row id
  std::uint64_t offset = 0;  ///< within the decompressed chunk
  std::uint64_t size = 0;    ///< the message's bytes
};

struct BagMessage {
  std::size_t topic = 0;            ///< index in topics()
  std::uint64_t index = 0;          ///< its index within its topic, from 0, in file order
  std::int64_t log_time_ns = 0;     ///< the recorder's time
  std::span<const std::byte> data;  ///< the serialized message, valid during the visit
  MessageRef where;
};

class BagReader {
 public:
  virtual ~BagReader() = default;
  virtual BagFormat format() const = 0;
  const std::filesystem::path& path() const { return path_; }

  /// Every topic of the bag (known at open from the bag's connections, channels or metadata).
  const std::vector<BagTopic>& topics() const { return topics_; }
  std::optional<std::size_t> find_topic(const std::string& name) const;
  /// True when the counts in topics() come from an index or summary (no pass needed).
  bool counts_known() const { return counts_known_; }

  /// One pass over every message in file order; `wanted[t]` selects topic t (empty: all). After a pass,
  /// topics()' counts are the messages seen.
  void for_each(const std::vector<bool>& wanted, const std::function<void(const BagMessage&)>& visit);
  /// The bytes of the message at `where` (from a visit).
  virtual std::vector<std::byte> read(const MessageRef& where) = 0;

  /// What a topic's index says without a pass: its first and last message times and its first message.
  struct IndexedTopic {
    std::int64_t first_ns = 0, last_ns = 0;
    std::vector<std::byte> first_message;
  };
  /// Per topic (topics() order), from the bag's index when it has one that tells (ROS 1 bags with an index:
  /// no chunk is decompressed but the first holding each topic); nullopt otherwise (a pass is needed).
  virtual std::optional<std::vector<IndexedTopic>> indexed_topics() { return std::nullopt; }

  /// Set when a pass met the end of the file inside a record: what was read, in words.
  const std::optional<std::string>& truncated() const { return truncated_; }

 protected:
  explicit BagReader(std::filesystem::path path) : path_(std::move(path)) {}
  /// The format's pass: calls emit(topic, log time, data, where) for every message in file order.
  using Emit = std::function<void(std::size_t, std::int64_t, std::span<const std::byte>, const MessageRef&)>;
  virtual void pass(const std::vector<bool>& wanted, const Emit& emit) = 0;

  std::filesystem::path path_;
  std::vector<BagTopic> topics_;
  bool counts_known_ = false;
  std::optional<std::string> truncated_;
};

/// The last two decompressed chunks, by file offset: a frame's messages of several topics usually lie in one
/// or two neighbouring chunks.
class ChunkCache {
 public:
  /// The chunk at `offset`, decompressed by `load` when not cached.
  std::span<const std::byte> get(std::uint64_t offset, const std::function<ChunkData()>& load) {
    for (const Entry& e : entries_)
      if (e.offset == offset) return e.data.view;
    Entry& slot = entries_[next_];
    next_ = 1 - next_;
    slot = {offset, load()};
    return slot.data.view;
  }
  void put(std::uint64_t offset, ChunkData data) {
    for (Entry& e : entries_)
      if (e.offset == offset) return;
    entries_[next_] = {offset, std::move(data)};
    next_ = 1 - next_;
  }

 private:
  struct Entry {
    std::uint64_t offset = UINT64_MAX;
    ChunkData data;
  };
  Entry entries_[2];
  int next_ = 0;
};

/// A reader for `path`: a .bag file (ROS 1), a .mcap file, a rosbag2 folder (metadata.yaml) or a .db3 file
/// inside one. InputError naming the path when it is none of them.
std::unique_ptr<BagReader> open_bag(const std::filesystem::path& path);

std::unique_ptr<BagReader> open_ros1_bag(const std::filesystem::path& path);
std::unique_ptr<BagReader> open_mcap(const std::filesystem::path& path);
std::unique_ptr<BagReader> open_rosbag2(const std::filesystem::path& folder);

}  // namespace mlidar::io
