// PCD files whose bytes are written out here by hand (ascii, binary and
// binary_compressed with a hand-built LZF block), read into known values; and
// the writer's bytes for a tiny cloud against the expected bytes. Unlike the
// round trips, a bug shared by the reader and the writer fails these.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

#include "test_pcd_support.hpp"

namespace mlidar::io {
namespace {

using test::to_bytes;

/// `text` (the header) followed by the raw bytes.
std::vector<std::byte> file_of(const std::string& text, std::initializer_list<unsigned> raw) {
  std::vector<std::byte> bytes = to_bytes(text);
  for (const unsigned byte : raw) bytes.push_back(static_cast<std::byte>(byte));
  return bytes;
}

/// Element `element` of point `point` of `column`, its bytes taken as a T (no library conversion).
template <typename T>
T element_of(const FieldColumn& column, std::size_t point, std::uint32_t element = 0) {
  EXPECT_EQ(column.stride() % sizeof(T), 0u) << column.name;
  T value{};
  std::memcpy(&value, column.data.data() + point * column.stride() + element * sizeof(T), sizeof(T));
  return value;
}

/// The bytes as a string, so that a mismatch prints both sides.
std::string as_text(const std::vector<std::byte>& bytes) { return {reinterpret_cast<const char*>(bytes.data()), bytes.size()}; }

const FieldColumn& column_named(const PointTable& table, const std::string& name) {
  const FieldColumn* column = table.find(name);
  EXPECT_NE(column, nullptr) << name;
  static const FieldColumn kMissing;
  return column != nullptr ? *column : kMissing;
}

void expect_layout(const PointTable& table, std::size_t field, const std::string& name, ScalarType type, std::uint32_t count) {
  ASSERT_LT(field, table.fields.size());
  EXPECT_EQ(table.fields[field].name, name);
  EXPECT_EQ(table.fields[field].type, type) << name;
  EXPECT_EQ(table.fields[field].count, count) << name;
}

TEST(PcdBytes, AsciiFileWrittenByHand) {
  const std::string file =
      "# .PCD v0.7 - Point Cloud Data file format\n"
      "VERSION 0.7\n"
      "FIELDS x y z intensity ring\n"
      "SIZE 4 4 4 4 2\n"
      "TYPE F F F F U\n"
      "COUNT 1 1 1 1 1\n"
      "WIDTH 3\n"
      "HEIGHT 1\n"
      "VIEWPOINT 1 2 3 0.5 0.5 -0.5 0.5\n"
      "POINTS 3\n"
      "DATA ascii\n"
      "1.5 -2.25 0.125 10 0\n"
      "-7 8.5 1e-3 255 15\n"
      "nan 0 -0 0.5 65535\n";
  const PcdCloud cloud = parse_pcd(to_bytes(file), "by_hand.pcd");
  EXPECT_EQ(cloud.version, "0.7");
  EXPECT_EQ(cloud.encoding, PcdEncoding::kAscii);
  EXPECT_EQ(cloud.viewpoint, (std::array<double, 7>{1, 2, 3, 0.5, 0.5, -0.5, 0.5}));
  const PointTable& table = cloud.table;
  EXPECT_EQ(table.num_points, 3u);
  EXPECT_EQ(table.width, 3u);
  EXPECT_EQ(table.height, 1u);
  ASSERT_EQ(table.fields.size(), 5u);
  expect_layout(table, 0, "x", ScalarType::kF32, 1);
  expect_layout(table, 3, "intensity", ScalarType::kF32, 1);
  expect_layout(table, 4, "ring", ScalarType::kU16, 1);
  const FieldColumn& x = column_named(table, "x");
  const FieldColumn& y = column_named(table, "y");
  const FieldColumn& z = column_named(table, "z");
  const FieldColumn& intensity = column_named(table, "intensity");
  const FieldColumn& ring = column_named(table, "ring");
  EXPECT_EQ(element_of<float>(x, 0), 1.5F);
  EXPECT_EQ(element_of<float>(y, 0), -2.25F);
  EXPECT_EQ(element_of<float>(z, 0), 0.125F);
  EXPECT_EQ(element_of<float>(intensity, 0), 10.0F);
  EXPECT_EQ(element_of<std::uint16_t>(ring, 0), 0u);
  EXPECT_EQ(element_of<float>(x, 1), -7.0F);
  EXPECT_EQ(element_of<float>(y, 1), 8.5F);
  EXPECT_EQ(element_of<float>(z, 1), 1e-3F);
  EXPECT_EQ(element_of<float>(intensity, 1), 255.0F);
  EXPECT_EQ(element_of<std::uint16_t>(ring, 1), 15u);
  EXPECT_TRUE(std::isnan(element_of<float>(x, 2)));
  EXPECT_EQ(element_of<float>(y, 2), 0.0F);
  EXPECT_TRUE(std::signbit(element_of<float>(z, 2)));  // -0 kept
  EXPECT_EQ(element_of<float>(intensity, 2), 0.5F);
  EXPECT_EQ(element_of<std::uint16_t>(ring, 2), 65535u);
}

// Two packed records of 18 bytes, little endian: x F4, i I2, two padding bytes, c U1 x 2, d F8.
TEST(PcdBytes, BinaryFileWrittenByHand) {
  const std::string header =
      "VERSION 0.6\n"
      "FIELDS x i _ c d\n"
      "SIZE 4 2 1 1 8\n"
      "TYPE F I U U F\n"
      "COUNT 1 1 2 2 1\n"
      "WIDTH 1\n"
      "HEIGHT 2\n"
      "VIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS 2\n"
      "DATA binary\n";
  const std::vector<std::byte> file = file_of(header, {
                                                          0x00, 0x00, 0x80, 0x3F,                          // x = 1.0f
                                                          0xFE, 0xFF,                                      // i = -2
                                                          0xAA, 0xBB,                                      // padding
                                                          0x07, 0xC8,                                      // c = 7, 200
                                                          0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0x3F,  // d = 0.5
                                                          0x00, 0x00, 0x20, 0xC0,                          // x = -2.5f
                                                          0x2C, 0x01,                                      // i = 300
                                                          0xCC, 0xDD,                                      // padding
                                                          0xFF, 0x00,                                      // c = 255, 0
                                                          0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08, 0xC0,  // d = -3.0
                                                      });
  const PcdCloud cloud = parse_pcd(file, "by_hand.pcd");
  EXPECT_EQ(cloud.version, "0.6");
  EXPECT_EQ(cloud.encoding, PcdEncoding::kBinary);
  const PointTable& table = cloud.table;
  EXPECT_EQ(table.num_points, 2u);
  EXPECT_EQ(table.width, 1u);
  EXPECT_EQ(table.height, 2u);
  ASSERT_EQ(table.fields.size(), 5u);
  expect_layout(table, 0, "x", ScalarType::kF32, 1);
  expect_layout(table, 1, "i", ScalarType::kI16, 1);
  expect_layout(table, 2, "_", ScalarType::kU8, 2);
  expect_layout(table, 3, "c", ScalarType::kU8, 2);
  expect_layout(table, 4, "d", ScalarType::kF64, 1);
  const FieldColumn& x = table.fields[0];
  const FieldColumn& i = table.fields[1];
  const FieldColumn& padding = table.fields[2];
  const FieldColumn& c = table.fields[3];
  const FieldColumn& d = table.fields[4];
  EXPECT_EQ(element_of<float>(x, 0), 1.0F);
  EXPECT_EQ(element_of<float>(x, 1), -2.5F);
  EXPECT_EQ(element_of<std::int16_t>(i, 0), -2);
  EXPECT_EQ(element_of<std::int16_t>(i, 1), 300);
  EXPECT_EQ(element_of<std::uint8_t>(padding, 0, 0), 0xAA);  // binary keeps padding bytes
  EXPECT_EQ(element_of<std::uint8_t>(padding, 0, 1), 0xBB);
  EXPECT_EQ(element_of<std::uint8_t>(padding, 1, 0), 0xCC);
  EXPECT_EQ(element_of<std::uint8_t>(padding, 1, 1), 0xDD);
  EXPECT_EQ(element_of<std::uint8_t>(c, 0, 0), 7);
  EXPECT_EQ(element_of<std::uint8_t>(c, 0, 1), 200);
  EXPECT_EQ(element_of<std::uint8_t>(c, 1, 0), 255);
  EXPECT_EQ(element_of<std::uint8_t>(c, 1, 1), 0);
  EXPECT_EQ(element_of<double>(d, 0), 0.5);
  EXPECT_EQ(element_of<double>(d, 1), -3.0);
}

// binary_compressed: uint32 compressed size, uint32 uncompressed size, then an LZF block holding the
// columns one after another (PCL leaves the padding column out). The block is two LZF literal runs,
// each a control byte L - 1 (< 32) followed by its L bytes: 10 + 8 = 18 bytes of columns in 20 bytes.
TEST(PcdBytes, BinaryCompressedFileWithAHandBuiltLzfBlock) {
  const std::string header =
      "# .PCD v0.7 - Point Cloud Data file format\n"
      "VERSION 0.7\n"
      "FIELDS x y _ intensity\n"
      "SIZE 4 4 1 1\n"
      "TYPE F F U U\n"
      "COUNT 1 1 1 1\n"
      "WIDTH 2\n"
      "HEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS 2\n"
      "DATA binary_compressed\n";
  const std::vector<std::byte> file =
      file_of(header, {
                          0x14, 0x00, 0x00, 0x00,  // compressed size 20
                          0x12, 0x00, 0x00, 0x00,  // uncompressed size 18 = 2 x (4 + 4 + 1), padding left out
                          0x09,                    // literal run of 10 bytes
                          0x00, 0x00, 0x80, 0x3F,  //   x[0] = 1.0f
                          0x00, 0x00, 0x20, 0xC0,  //   x[1] = -2.5f
                          0x00, 0x00,              //   y[0] = 0.5f, first half
                          0x07,                    // literal run of 8 bytes
                          0x00, 0x3F,              //   y[0], second half
                          0x00, 0x00, 0x40, 0x41,  //   y[1] = 12.0f
                          0x05, 0xFA,              //   intensity = 5, 250
                      });
  const PcdCloud cloud = parse_pcd(file, "by_hand.pcd");
  EXPECT_EQ(cloud.encoding, PcdEncoding::kBinaryCompressed);
  const PointTable& table = cloud.table;
  EXPECT_EQ(table.num_points, 2u);
  ASSERT_EQ(table.fields.size(), 4u);
  expect_layout(table, 2, "_", ScalarType::kU8, 1);
  expect_layout(table, 3, "intensity", ScalarType::kU8, 1);
  EXPECT_EQ(element_of<float>(table.fields[0], 0), 1.0F);
  EXPECT_EQ(element_of<float>(table.fields[0], 1), -2.5F);
  EXPECT_EQ(element_of<float>(table.fields[1], 0), 0.5F);
  EXPECT_EQ(element_of<float>(table.fields[1], 1), 12.0F);
  EXPECT_EQ(element_of<std::uint8_t>(table.fields[2], 0), 0);  // left out of the block: zero
  EXPECT_EQ(element_of<std::uint8_t>(table.fields[2], 1), 0);
  EXPECT_EQ(element_of<std::uint8_t>(table.fields[3], 0), 5);
  EXPECT_EQ(element_of<std::uint8_t>(table.fields[3], 1), 250);
}

/// Two points: x (float32) 1.0, -2.5 and ring (uint16) 5, 513.
PcdCloud tiny_cloud(PcdEncoding encoding) {
  PcdCloud cloud;
  cloud.encoding = encoding;
  cloud.viewpoint = {1.5, -2, 0, 1, 0, 0, 0};
  cloud.table.num_points = 2;
  FieldColumn& x = cloud.table.add_field("x", ScalarType::kF32);
  const float xs[2] = {1.0F, -2.5F};
  std::memcpy(x.data.data(), xs, sizeof(xs));
  FieldColumn& ring = cloud.table.add_field("ring", ScalarType::kU16);
  const std::uint16_t rings[2] = {5, 513};
  std::memcpy(ring.data.data(), rings, sizeof(rings));
  return cloud;
}

std::string header_text(const std::string& data) {
  return "# .PCD v0.7 - Point Cloud Data file format\n"
         "VERSION 0.7\n"
         "FIELDS x ring\n"
         "SIZE 4 2\n"
         "TYPE F U\n"
         "COUNT 1 1\n"
         "WIDTH 2\n"
         "HEIGHT 1\n"
         "VIEWPOINT 1.5 -2 0 1 0 0 0\n"
         "POINTS 2\n"
         "DATA " +
         data + "\n";
}

TEST(PcdBytes, WriterEmitsTheExpectedBytesForATinyCloud) {
  const std::vector<std::byte> binary = file_of(header_text("binary"), {
                                                                           0x00, 0x00, 0x80, 0x3F, 0x05, 0x00,  // x = 1.0f, ring = 5
                                                                           0x00, 0x00, 0x20, 0xC0, 0x01, 0x02,  // x = -2.5f, ring = 513
                                                                       });
  EXPECT_EQ(as_text(encode_pcd(tiny_cloud(PcdEncoding::kBinary))), as_text(binary));
  EXPECT_EQ(as_text(encode_pcd(tiny_cloud(PcdEncoding::kAscii))), header_text("ascii") + "1 5\n-2.5 513\n");
  // 12 bytes of columns with no 3-byte repeat: LZF writes one literal run (control byte 11, then the 12 bytes).
  const std::vector<std::byte> compressed =
      file_of(header_text("binary_compressed"), {
                                                    0x0D, 0x00, 0x00, 0x00,                          // compressed size 13
                                                    0x0C, 0x00, 0x00, 0x00,                          // uncompressed size 12
                                                    0x0B,                                            // literal run of 12 bytes
                                                    0x00, 0x00, 0x80, 0x3F, 0x00, 0x00, 0x20, 0xC0,  // x column
                                                    0x05, 0x00, 0x01, 0x02,                          // ring column
                                                });
  EXPECT_EQ(as_text(encode_pcd(tiny_cloud(PcdEncoding::kBinaryCompressed))), as_text(compressed));
}

}  // namespace
}  // namespace mlidar::io
