#pragma once
// The ROS messages mlidar reads from bags, decoded from their ROS 1
// serialization (little-endian, uint32 lengths, strings without a NUL) or from
// CDR (ROS 2: a 4-byte encapsulation header giving the byte order, every
// primitive aligned to its size from the end of that header, strings with
// their NUL counted):
//   sensor_msgs/PointCloud2  -> header, layout and a PointTable with every field
//   tf2_msgs/TFMessage       -> parent, child and transform of each entry
// Every length is checked against the message: InputError naming `source`
// (e.g. "BAG: topic /top/points, message 12") and the field otherwise.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"
#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

enum class MessageEncoding : std::uint8_t { kRos1, kCdr };

struct RosTime {
  std::int64_t sec = 0;
  std::uint32_t nanosec = 0;
  double seconds() const { return static_cast<double>(sec) + 1e-9 * nanosec; }
  std::int64_t nanoseconds() const { return sec * 1000000000LL + nanosec; }
};

struct RosHeader {
  RosTime stamp;
  std::string frame_id;
};

struct PointCloud2 {
  RosHeader header;
  std::uint32_t height = 0, width = 0, point_step = 0, row_step = 0;
  bool is_bigendian = false, is_dense = false;
  struct Field {
    std::string name;
    std::uint32_t offset = 0;
    std::uint8_t datatype = 0;  ///< 1 INT8 .. 8 FLOAT64 (sensor_msgs/PointField)
    std::uint32_t count = 0;
  };
  std::vector<Field> fields;
  PointTable table;  ///< every point (height x width), every field with a known type, host byte order
};

/// `only`: decode just these fields into the table (nullptr: all); the layout is checked either way.
PointCloud2 decode_pointcloud2(std::span<const std::byte> message, MessageEncoding encoding, const std::string& source,
                               const std::vector<std::string>* only = nullptr);

struct RosTransform {
  RosHeader header;  ///< frame_id: the parent
  std::string child_frame_id;
  SE3 T_parent_child;
};

std::vector<RosTransform> decode_tf_message(std::span<const std::byte> message, MessageEncoding encoding, const std::string& source);

/// sensor_msgs/PointField datatype -> ScalarType; false for an unknown code.
bool pointfield_type(std::uint8_t datatype, ScalarType& type);

}  // namespace mlidar::io
