#include "mlidar/io/ros_messages.hpp"

#include <algorithm>
#include <set>

#include "mlidar/io/byte_reader.hpp"

namespace mlidar::io {
namespace {

/// Reads one message's primitives in its encoding: ROS 1 (packed, little-endian) or CDR (aligned, either order).
class MessageReader {
 public:
  MessageReader(std::span<const std::byte> message, MessageEncoding encoding, const std::string& source)
      : reader_(message, source), cdr_(encoding == MessageEncoding::kCdr) {
    if (!cdr_) return;
    const auto encapsulation = reader_.take(4, "CDR encapsulation header");
    const auto kind = std::to_integer<unsigned>(encapsulation[1]);
    if (std::to_integer<unsigned>(encapsulation[0]) != 0 || kind > 1)
      throw InputError(source, "CDR encapsulation header",
                       "kind " + std::to_string(kind) + " is not plain CDR (00 00 big-endian or 00 01 little-endian)");
    reader_.set_big_endian(kind == 0);
    origin_ = reader_.position();
  }

  template <typename T>
  T get(std::string_view what) {
    if (cdr_) reader_.align(sizeof(T), origin_);
    return reader_.scalar<T>(what);
  }

  std::string string(std::string_view what) {
    const std::uint32_t length = get<std::uint32_t>(what);
    const auto bytes = reader_.take(length, what);
    std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    if (cdr_) {  // the NUL is counted
      if (text.empty() || text.back() != '\0') throw InputError(reader_.source(), std::string(what), "CDR string without its NUL");
      text.pop_back();
    }
    return text;
  }

  /// A sequence's element count, checked against what remains (each element needs `min_size` bytes).
  std::uint32_t count(std::string_view what, std::size_t min_size) {
    const std::uint32_t n = get<std::uint32_t>(what);
    if (static_cast<std::uint64_t>(n) * min_size > reader_.remaining())
      throw InputError(
          reader_.source(), std::string(what),
          std::to_string(n) + " elements cannot fit in the " + std::to_string(reader_.remaining()) + " bytes left (a length that lies)");
    return n;
  }

  std::span<const std::byte> bytes(std::string_view what) { return reader_.take(count(what, 1), what); }

  RosHeader header() {
    RosHeader h;
    if (!cdr_) get<std::uint32_t>("header.seq");
    h.stamp.sec = cdr_ ? get<std::int32_t>("header.stamp.sec") : get<std::uint32_t>("header.stamp.sec");
    h.stamp.nanosec = get<std::uint32_t>("header.stamp.nanosec");
    h.frame_id = string("header.frame_id");
    return h;
  }

 private:
  ByteReader reader_;
  bool cdr_;
  std::size_t origin_ = 0;
};

std::vector<PointCloud2::Field> read_fields(MessageReader& in) {
  std::vector<PointCloud2::Field> fields(in.count("fields", 13));
  for (auto& f : fields) {
    f.name = in.string("fields.name");
    f.offset = in.get<std::uint32_t>("fields.offset");
    f.datatype = in.get<std::uint8_t>("fields.datatype");
    f.count = in.get<std::uint32_t>("fields.count");
  }
  return fields;
}

/// Copies `bytes` bytes at `offset` of every point to `out`, scalar by scalar in host order (each `size` bytes,
/// reversed when `swap`). The fixed sizes let the compiler inline the copies (a memcpy call per value was the
/// largest cost of exporting a bag).
template <std::size_t kSize>
void copy_values(std::span<const std::byte> data, const PointCloud2& cloud, std::size_t offset, std::size_t bytes, bool swap, std::byte* out) {
  for (std::uint32_t row = 0; row < cloud.height; ++row) {
    const std::byte* point = data.data() + static_cast<std::size_t>(row) * cloud.row_step + offset;
    for (std::uint32_t col = 0; col < cloud.width; ++col, point += cloud.point_step) {
      for (std::size_t e = 0; e < bytes; e += kSize, out += kSize) {
        std::memcpy(out, point + e, kSize);
        if (swap && kSize > 1) std::reverse(out, out + kSize);
      }
    }
  }
}

void copy_field(std::span<const std::byte> data, const PointCloud2& cloud, std::size_t offset, std::size_t bytes, std::size_t size, bool swap,
                std::byte* out) {
  switch (size) {
    case 1: return copy_values<1>(data, cloud, offset, bytes, swap, out);
    case 2: return copy_values<2>(data, cloud, offset, bytes, swap, out);
    case 4: return copy_values<4>(data, cloud, offset, bytes, swap, out);
    default: return copy_values<8>(data, cloud, offset, bytes, swap, out);
  }
}

/// Checks the layout and copies every field of every point into host order.
PointTable to_table(const PointCloud2& cloud, std::span<const std::byte> data, const std::string& source,
                    const std::vector<std::string>* only) {
  const std::uint64_t points = static_cast<std::uint64_t>(cloud.height) * cloud.width;
  if (points > 0) {
    if (cloud.point_step == 0) throw InputError(source, "point_step", "is 0 for " + std::to_string(points) + " points");
    // Each product is below 2^64 (32-bit factors); their sum may not be.
    const std::uint64_t rows = static_cast<std::uint64_t>(cloud.height - 1) * cloud.row_step;
    const std::uint64_t last = static_cast<std::uint64_t>(cloud.width) * cloud.point_step;
    const std::uint64_t needed = rows > UINT64_MAX - last ? UINT64_MAX : rows + last;
    if (static_cast<std::uint64_t>(cloud.width) * cloud.point_step > cloud.row_step && cloud.height > 1)
      throw InputError(source, "row_step", "is " + std::to_string(cloud.row_step) + ", less than width x point_step");
    if (data.size() < needed)
      throw InputError(source, "data",
                       "holds " + std::to_string(data.size()) + " bytes, less than height, width, point_step and row_step need (" +
                           std::to_string(cloud.height) + " x " + std::to_string(cloud.width) + " points of " +
                           std::to_string(cloud.point_step) + " bytes)");
  }
  PointTable table;
  table.num_points = static_cast<std::size_t>(points);
  table.width = cloud.width;
  table.height = cloud.height;
  std::set<std::string> names;
  for (const auto& f : cloud.fields) {
    ScalarType type;
    if (!pointfield_type(f.datatype, type))
      throw InputError(source, "fields." + f.name, "datatype " + std::to_string(f.datatype) + " is no sensor_msgs/PointField type (1-8)");
    if (!names.insert(f.name).second) throw InputError(source, "fields." + f.name, "given twice");
    const std::size_t size = scalar_size(type), count = std::max<std::uint32_t>(f.count, 1);
    if (f.offset + size * count > cloud.point_step)
      throw InputError(
          source, "fields." + f.name,
          "ends at byte " + std::to_string(f.offset + size * count) + ", beyond point_step " + std::to_string(cloud.point_step));
    if (only != nullptr && std::find(only->begin(), only->end(), f.name) == only->end()) continue;
    FieldColumn& column = table.add_field(f.name, type, static_cast<std::uint32_t>(count));
    const bool swap = cloud.is_bigendian != (std::endian::native == std::endian::big);
    // Not when empty: a width of 0 under a height of 10^9 would walk every empty row.
    if (points > 0) copy_field(data, cloud, f.offset, size * count, size, swap, column.data.data());
  }
  return table;
}

}  // namespace

bool pointfield_type(std::uint8_t datatype, ScalarType& type) {
  constexpr ScalarType kTypes[] = {ScalarType::kI8,  ScalarType::kU8,  ScalarType::kI16, ScalarType::kU16,
                                   ScalarType::kI32, ScalarType::kU32, ScalarType::kF32, ScalarType::kF64};
  if (datatype < 1 || datatype > 8) return false;
  type = kTypes[datatype - 1];
  return true;
}

PointCloud2 decode_pointcloud2(std::span<const std::byte> message, MessageEncoding encoding, const std::string& source,
                               const std::vector<std::string>* only) {
  MessageReader in(message, encoding, source);
  PointCloud2 cloud;
  cloud.header = in.header();
  cloud.height = in.get<std::uint32_t>("height");
  cloud.width = in.get<std::uint32_t>("width");
  cloud.fields = read_fields(in);
  cloud.is_bigendian = in.get<std::uint8_t>("is_bigendian") != 0;
  cloud.point_step = in.get<std::uint32_t>("point_step");
  cloud.row_step = in.get<std::uint32_t>("row_step");
  const std::span<const std::byte> data = in.bytes("data");
  cloud.is_dense = in.get<std::uint8_t>("is_dense") != 0;
  cloud.table = to_table(cloud, data, source, only);
  return cloud;
}

std::vector<RosTransform> decode_tf_message(std::span<const std::byte> message, MessageEncoding encoding, const std::string& source) {
  MessageReader in(message, encoding, source);
  std::vector<RosTransform> transforms(in.count("transforms", 64));
  for (auto& t : transforms) {
    t.header = in.header();
    t.child_frame_id = in.string("child_frame_id");
    double v[7];
    for (double& x : v) x = in.get<double>("transform");
    const Quat q(v[6], v[3], v[4], v[5]);
    if (!(std::abs(q.norm() - 1.0) < 1e-3)) throw InputError(source, "transform.rotation", "is not a unit quaternion");
    t.T_parent_child = SE3(q, Vec3(v[0], v[1], v[2]));
  }
  return transforms;
}

}  // namespace mlidar::io
