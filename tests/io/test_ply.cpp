// PLY: crafted files in all three encodings (an oracle independent of the
// writer), writer round trips and one test per rejection rule.
#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "format_test_util.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/ply.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {
using test::bytes_of;
using test::expect_input_error;

template <typename T>
void fill(FieldColumn& column, std::initializer_list<T> values) {
  column.data.resize(values.size() * sizeof(T));
  std::memcpy(column.data.data(), std::data(values), column.data.size());
}

// Five points, one column per PLY scalar type, extremes included.
PointTable every_type_table() {
  PointTable table;
  table.num_points = 5;
  table.width = 5;
  using L8 = std::numeric_limits<std::int8_t>;
  using L16 = std::numeric_limits<std::int16_t>;
  using L32 = std::numeric_limits<std::int32_t>;
  fill<std::int8_t>(table.add_field("a_i8", ScalarType::kI8), {L8::min(), -1, 0, 1, L8::max()});
  fill<std::uint8_t>(table.add_field("b_u8", ScalarType::kU8), {0, 1, 127, 128, 255});
  fill<std::int16_t>(table.add_field("c_i16", ScalarType::kI16), {L16::min(), -300, 0, 300, L16::max()});
  fill<std::uint16_t>(table.add_field("d_u16", ScalarType::kU16), {0, 1, 256, 4660, 65535});
  fill<std::int32_t>(table.add_field("e_i32", ScalarType::kI32), {L32::min(), -70000, 0, 70000, L32::max()});
  fill<std::uint32_t>(table.add_field("f_u32", ScalarType::kU32), {0, 1, 65536, 305419896, 4294967295u});
  fill<float>(table.add_field("x", ScalarType::kF32), {0.1f, -2.5e-30f, 1e30f, -0.0f, 1.17549435e-38f});
  fill<double>(table.add_field("y", ScalarType::kF64), {0.1, -1e-300, 1e300, 3.141592653589793, 5e-324});
  return table;
}

const char* sized_type_name(ScalarType type) { return scalar_name(type); }  // "int8", "float32", ...

std::string ascii_value(const FieldColumn& column, std::size_t i) {
  std::array<char, 64> text{};
  const std::byte* p = column.data.data() + i * column.stride();
  const auto print = [&]<typename T>(T value) {
    std::memcpy(&value, p, sizeof(T));
    if constexpr (sizeof(T) == 1) return std::to_string(static_cast<int>(value));
    const auto [end, ec] = std::to_chars(text.data(), text.data() + text.size(), value);
    return std::string(text.data(), end);
  };
  switch (column.type) {
    case ScalarType::kI8:
      return print(std::int8_t{});
    case ScalarType::kU8:
      return print(std::uint8_t{});
    case ScalarType::kI16:
      return print(std::int16_t{});
    case ScalarType::kU16:
      return print(std::uint16_t{});
    case ScalarType::kI32:
      return print(std::int32_t{});
    case ScalarType::kU32:
      return print(std::uint32_t{});
    case ScalarType::kF32:
      return print(float{});
    default:
      return print(double{});
  }
}

// Appends raw bytes of a scalar, reversed for big endian (the host is little endian).
template <typename T>
void put(std::string& out, T value, bool big_endian) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (big_endian) std::reverse(raw, raw + sizeof(T));
  out.append(raw, sizeof(T));
}

// A PLY written by hand: a `camera` element (scalar + list) before the
// vertices and a `face` element (list + scalar) after them.
std::string craft_ply(const PointTable& table, PlyEncoding encoding) {
  std::string text = std::string("ply\nformat ") + ply_encoding_name(encoding) + " 1.0\ncomment crafted by hand\nobj_info x\n";
  text += "element camera 2\nproperty float focal\nproperty list uchar int ids\n";
  text += "element vertex " + std::to_string(table.num_points) + "\n";
  for (const auto& column : table.fields) text += std::string("property ") + sized_type_name(column.type) + " " + column.name + "\n";
  text += "element face 2\nproperty list uchar int vertex_indices\nproperty uchar flags\nend_header\n";
  if (encoding == PlyEncoding::kAscii) {
    text += "1.5 3 7 8 9\n2.5 0\n";
    for (std::size_t i = 0; i < table.num_points; ++i) {
      for (const auto& column : table.fields) text += ascii_value(column, i) + " ";
      text += "\n";
    }
    return text + "3 0 1 2 9\n4 0 1 2 3 7\n";
  }
  const bool big = encoding == PlyEncoding::kBinaryBigEndian;
  put(text, 1.5f, big), put<std::uint8_t>(text, 3, big);
  for (std::int32_t id : {7, 8, 9}) put(text, id, big);
  put(text, 2.5f, big), put<std::uint8_t>(text, 0, big);
  for (std::size_t i = 0; i < table.num_points; ++i) {
    for (const auto& column : table.fields) {
      std::string raw(reinterpret_cast<const char*>(column.data.data() + i * column.stride()), column.stride());
      if (big) std::reverse(raw.begin(), raw.end());
      text += raw;
    }
  }
  put<std::uint8_t>(text, 3, big);
  for (std::int32_t id : {0, 1, 2}) put(text, id, big);
  put<std::uint8_t>(text, 9, big);
  put<std::uint8_t>(text, 4, big);
  for (std::int32_t id : {0, 1, 2, 3}) put(text, id, big);
  put<std::uint8_t>(text, 7, big);
  return text;
}

void expect_same_table(const PointTable& expected, const PointTable& actual) {
  ASSERT_EQ(actual.num_points, expected.num_points);
  ASSERT_EQ(actual.fields.size(), expected.fields.size());
  for (std::size_t k = 0; k < expected.fields.size(); ++k) {
    EXPECT_EQ(actual.fields[k].name, expected.fields[k].name);
    EXPECT_EQ(actual.fields[k].type, expected.fields[k].type) << expected.fields[k].name;
    EXPECT_EQ(actual.fields[k].data, expected.fields[k].data) << expected.fields[k].name << " differs bit for bit";
  }
}

class PlyEncodings : public ::testing::TestWithParam<PlyEncoding> {};

TEST_P(PlyEncodings, ReadsEveryTypeAndSkipsListElementsAroundVertices) {
  const PointTable table = every_type_table();
  const std::string text = craft_ply(table, GetParam());
  const PlyCloud cloud = parse_ply(bytes_of(text), "crafted.ply");
  EXPECT_EQ(cloud.encoding, GetParam());
  ASSERT_EQ(cloud.comments.size(), 1u);
  EXPECT_EQ(cloud.comments[0], "crafted by hand");
  expect_same_table(table, cloud.table);
}

TEST_P(PlyEncodings, WriterRoundTripIsBitIdentical) {
  const PointTable table = every_type_table();
  const PlyCloud read = parse_ply(bytes_of(craft_ply(table, GetParam())), "crafted.ply");
  const std::vector<std::byte> encoded = encode_ply(read);
  const PlyCloud back = parse_ply(encoded, "encoded.ply");
  EXPECT_EQ(back.encoding, PlyEncoding::kBinaryLittleEndian);
  EXPECT_EQ(back.comments, read.comments);
  expect_same_table(table, back.table);
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PlyEncodings,
                         ::testing::Values(PlyEncoding::kAscii, PlyEncoding::kBinaryLittleEndian, PlyEncoding::kBinaryBigEndian));

TEST(PlyWriter, MultiElementColumnsBecomeNumberedPropertiesAndFileIsWritten) {
  PointTable table;
  table.num_points = 2;
  fill<float>(table.add_field("x", ScalarType::kF32), {1.f, 2.f});
  fill<double>(table.add_field("normal", ScalarType::kF64, 3), {0.1, 0.2, 0.3, 0.4, 0.5, 0.6});
  fill<std::uint64_t>(table.add_field("stamp", ScalarType::kU64), {1700000000123456789ull >> 8, 42});
  const auto path = test::scratch_dir() / "cloud.ply";
  write_ply(path, PlyCloud{PlyEncoding::kBinaryLittleEndian, {"hello"}, table});
  const PlyCloud back = read_ply(path);
  ASSERT_EQ(back.table.fields.size(), 5u);
  for (int k = 0; k < 3; ++k) {
    const FieldColumn& column = back.table.fields[static_cast<std::size_t>(1 + k)];
    EXPECT_EQ(column.name, "normal_" + std::to_string(k));
    EXPECT_EQ(column.value(1), table.fields[1].value(1, static_cast<std::uint32_t>(k)));
  }
  EXPECT_EQ(back.table.fields[4].type, ScalarType::kF64);  // no 64-bit integers in PLY: exact as float64
  EXPECT_EQ(back.table.fields[4].value(0), static_cast<double>(1700000000123456789ull >> 8));
}

TEST(PlyWriter, RefusesIntegersDoublesCannotHold) {
  PointTable table;
  table.num_points = 1;
  fill<std::uint64_t>(table.add_field("stamp", ScalarType::kU64), {(1ull << 53) + 1});
  EXPECT_THROW(encode_ply(PlyCloud{PlyEncoding::kBinaryLittleEndian, {}, table}), OutputError);
}

TEST(PlyRealData, ScanPairMatchesItsPcdTwinsPointForPoint) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto folder = test::shared_data() / "real/scan_pair";
  for (const auto& [ply, pcd] : {std::pair{"source.ply", "251371071.pcd"}, std::pair{"target.ply", "251370668.pcd"}}) {
    const PlyCloud cloud = read_ply(folder / ply);
    EXPECT_EQ(cloud.encoding, PlyEncoding::kBinaryLittleEndian);
    ASSERT_EQ(cloud.table.fields.size(), 4u);
    EXPECT_EQ(cloud.table.fields[3].name, "scalar_intensity");
    ASSERT_TRUE(std::ranges::any_of(cloud.comments, [](const std::string& c) { return c.starts_with("Created by CloudCompare"); }));
    // The PCD twin is `DATA binary` with x y z intensity float32: its body is read directly.
    const std::string twin = read_file_text(folder / pcd);
    const std::size_t body = twin.find("DATA binary\n") + 12;
    ASSERT_EQ(twin.size() - body, cloud.table.num_points * 16) << pcd;
    for (std::size_t i = 0; i < cloud.table.num_points; i += 97) {
      for (std::size_t k = 0; k < 4; ++k) {
        float expected;
        std::memcpy(&expected, twin.data() + body + 16 * i + 4 * k, 4);
        ASSERT_EQ(cloud.table.fields[k].value(i), static_cast<double>(expected)) << ply << " point " << i << " field " << k;
      }
    }
  }
}

TEST(PlyRejects, MissingMagic) {
  expect_input_error([] { parse_ply(bytes_of("plyx\nformat ascii 1.0\n"), "m.ply"); }, {"m.ply", "'ply' magic"});
}

TEST(PlyRejects, UnknownFormat) {
  expect_input_error([] { parse_ply(bytes_of("ply\nformat binary_middle_endian 1.0\nend_header\n"), "f.ply"); },
                     {"f.ply", "header line 2", "binary_middle_endian"});
}

TEST(PlyRejects, UnknownType) {
  expect_input_error([] { parse_ply(bytes_of("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n"), "t.ply"); },
                     {"t.ply", "header line 4", "unknown property type 'quad'"});
}

TEST(PlyRejects, PropertyBeforeElement) {
  expect_input_error([] { parse_ply(bytes_of("ply\nformat ascii 1.0\nproperty float x\nend_header\n"), "p.ply"); },
                     {"p.ply", "header line 3", "before any element"});
}

TEST(PlyRejects, NoVertexElement) {
  expect_input_error([] { parse_ply(bytes_of("ply\nformat ascii 1.0\nelement face 0\nproperty float x\nend_header\n"), "v.ply"); },
                     {"v.ply", "element vertex", "missing"});
}

TEST(PlyRejects, BinaryDataShorterThanPromised) {
  const std::string text = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nend_header\n" + std::string(11, '\0');
  expect_input_error([&] { parse_ply(bytes_of(text), "b.ply"); }, {"b.ply", "element vertex", "promises 3 rows"});
}

TEST(PlyRejects, AsciiDataShorterThanPromised) {
  const std::string text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nend_header\n1 2\n3 4\n5      \n";
  expect_input_error([&] { parse_ply(bytes_of(text), "a.ply"); }, {"a.ply", "element vertex row 2 property y", "ends early"});
}

TEST(PlyRejects, AbsurdCountWithoutOverflow) {
  const std::string text =
      "ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\nproperty double x\n"
      "property double y\nend_header\n" +
      std::string(64, '\0');
  expect_input_error([&] { parse_ply(bytes_of(text), "c.ply"); }, {"c.ply", "element vertex", "promises 18446744073709551615 rows"});
  expect_input_error([&] { parse_ply(bytes_of("ply\nformat ascii 1.0\nelement vertex 99999999999999999999\nend_header\n"), "c.ply"); },
                     {"c.ply", "header line 3", "element count"});
}

TEST(PlyRejects, ListCountRunningPastTheData) {
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
      "element face 1\nproperty list uint int idx\nend_header\n" +
      std::string(4, '\0');
  put<std::uint32_t>(binary, 1000000000u, false);
  binary += std::string(8, '\0');
  expect_input_error([&] { parse_ply(bytes_of(binary), "l.ply"); }, {"l.ply", "element face row 0 property idx", "runs past"});
  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement face 1\n"
      "property list uchar int idx\nend_header\n1\n200 1 2 3\n";
  expect_input_error([&] { parse_ply(bytes_of(ascii), "l.ply"); }, {"l.ply", "element face row 0 property idx", "runs past"});
}

TEST(PlyRejects, AsciiValueOutOfItsTypesRange) {
  const std::string text = "ply\nformat ascii 1.0\nelement vertex 1\nproperty uchar r\nend_header\n256\n";
  expect_input_error([&] { parse_ply(bytes_of(text), "r.ply"); }, {"r.ply", "property r", "not a valid uint8"});
}

TEST(PlyRejects, MissingFileNamesThePath) {
  expect_input_error([] { read_ply("/nonexistent/cloud.ply"); }, {"/nonexistent/cloud.ply", "no such file"});
}

}  // namespace
}  // namespace mlidar::io
