#pragma once
// A minimal ROS 1 bag v2.0 writer for the tests' broken bags, written from the
// format's description (wiki.ros.org/Bags/Format/2.0), not from mlidar's
// reader: a version line, a bag header without index, one chunk (compression
// "none" or another name) holding a connection and its messages.
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace mlidar::test {

inline void put_u32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }
inline void put_u64(std::string& out, std::uint64_t v) { out.append(reinterpret_cast<const char*>(&v), 8); }

inline std::string bag_field(const std::string& name, const std::string& value) {
  std::string out;
  put_u32(out, static_cast<std::uint32_t>(name.size() + 1 + value.size()));
  return out + name + "=" + value;
}

inline std::string bag_record(const std::string& header, const std::string& data) {
  std::string out;
  put_u32(out, static_cast<std::uint32_t>(header.size()));
  out += header;
  put_u32(out, static_cast<std::uint32_t>(data.size()));
  return out + data;
}

inline std::string u32_value(std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
inline std::string u64_value(std::uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); }

struct RosField {
  std::string name;
  std::uint32_t offset;
  std::uint8_t datatype;  // 7 = FLOAT32
};

/// sensor_msgs/PointCloud2 in ROS 1 serialization.
inline std::string pointcloud2(std::uint32_t width, std::uint32_t point_step, const std::vector<RosField>& fields, std::size_t data_bytes) {
  std::string m;
  put_u32(m, 0);           // seq
  put_u32(m, 1700000000);  // stamp.sec
  put_u32(m, 0);           // stamp.nsec
  put_u32(m, 3);
  m += "pts";     // frame_id
  put_u32(m, 1);  // height
  put_u32(m, width);
  put_u32(m, static_cast<std::uint32_t>(fields.size()));
  for (const RosField& f : fields) {
    put_u32(m, static_cast<std::uint32_t>(f.name.size()));
    m += f.name;
    put_u32(m, f.offset);
    m += static_cast<char>(f.datatype);
    put_u32(m, 1);
  }
  m += '\0';  // is_bigendian
  put_u32(m, point_step);
  put_u32(m, point_step * width);  // row_step
  put_u32(m, static_cast<std::uint32_t>(data_bytes));
  m += std::string(data_bytes, '\0');
  m += '\1';  // is_dense
  return m;
}

/// A bag with topic /pts (sensor_msgs/PointCloud2) holding `messages`; its chunk's compression and its claimed
/// uncompressed size as given (0: the true size).
inline void write_bag(const std::string& path, const std::vector<std::string>& messages, const std::string& compression = "none",
                      std::uint32_t claimed_size = 0) {
  std::string records;
  const std::string connection_header = bag_field("op", "\x07") + bag_field("conn", u32_value(0)) + bag_field("topic", "/pts");
  const std::string connection_data =
      bag_field("topic", "/pts") + bag_field("type", "sensor_msgs/PointCloud2") + bag_field("md5sum", "1158d486dd51d683ce2f1be655c3c181");
  records += bag_record(connection_header, connection_data);
  for (std::size_t i = 0; i < messages.size(); ++i) {
    const std::uint64_t time = 1700000000ULL | (static_cast<std::uint64_t>(i * 100000000) << 32);
    records += bag_record(bag_field("op", "\x02") + bag_field("conn", u32_value(0)) + bag_field("time", u64_value(time)), messages[i]);
  }
  const std::string chunk_header =
      bag_field("op", "\x05") + bag_field("compression", compression) +
      bag_field("size", u32_value(claimed_size > 0 ? claimed_size : static_cast<std::uint32_t>(records.size())));
  std::string bag = "#ROSBAG V2.0\n";
  const std::string bag_header = bag_field("op", "\x03") + bag_field("index_pos", u64_value(0)) + bag_field("conn_count", u32_value(1)) +
                                 bag_field("chunk_count", u32_value(1));
  bag += bag_record(bag_header, std::string(4096 - bag_header.size() - 8, ' '));
  bag += bag_record(chunk_header, records);
  std::ofstream(path, std::ios::binary) << bag;
}

}  // namespace mlidar::test
