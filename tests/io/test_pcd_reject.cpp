// One crafted broken file per rejection rule: each must throw InputError
// naming the file and the header field at fault. Truncated real files too.
#include <cmath>
#include <cstring>
#include <random>

#include "mlidar/io/file_bytes.hpp"
#include "test_pcd_support.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {

using test::expect_rejected;
using test::to_bytes;

const std::string kHeader =
    "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
    "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n";
const std::string kAscii = kHeader + "DATA ascii\n1 2 3\n4 5 6\n";

// kAscii with the first occurrence of `from` replaced by `to`.
std::string edited(const std::string& from, const std::string& to, std::string text = kAscii) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

std::vector<std::byte> binary_file(std::size_t data_bytes, const std::string& header = kHeader) {
  auto bytes = to_bytes(header + "DATA binary\n");
  bytes.resize(bytes.size() + data_bytes, std::byte{0x3f});
  return bytes;
}

std::vector<std::byte> compressed_file() {
  PcdCloud cloud;
  cloud.encoding = PcdEncoding::kBinaryCompressed;
  cloud.table.num_points = 2;
  cloud.table.width = 2;
  for (const char* axis : {"x", "y", "z"}) cloud.table.add_field(axis, ScalarType::kF32);
  return encode_pcd(cloud);
}

std::size_t compressed_prefix_offset(const std::vector<std::byte>& file) {
  const std::string marker = "DATA binary_compressed\n";
  const std::string text(reinterpret_cast<const char*>(file.data()), file.size());
  return text.find(marker) + marker.size();
}

void set_u32(std::vector<std::byte>& bytes, std::size_t offset, std::uint32_t value) { std::memcpy(bytes.data() + offset, &value, 4); }

TEST(PcdReject, CraftedFilesParseWhenIntact) {
  EXPECT_EQ(parse_pcd(to_bytes(kAscii), "ok").table.num_points, 2u);
  EXPECT_EQ(parse_pcd(binary_file(24), "ok").table.num_points, 2u);
  EXPECT_EQ(parse_pcd(compressed_file(), "ok").table.num_points, 2u);
  // Optional lines take their defaults: COUNT 1, VIEWPOINT identity, POINTS = WIDTH * HEIGHT.
  const std::string minimal = "VERSION .7\nFIELDS x\nSIZE 8\nTYPE F\nWIDTH 1\nHEIGHT 2\nDATA ascii\n1.5\n-2\n";
  const PcdCloud cloud = parse_pcd(to_bytes(minimal), "ok");
  EXPECT_EQ(cloud.table.num_points, 2u);
  EXPECT_EQ(cloud.table.height, 2u);
  EXPECT_EQ(cloud.table.fields[0].value(1), -2.0);
}

TEST(PcdReject, UnknownAndMissingHeaderLines) {
  expect_rejected(edited("WIDTH 2\n", "COLOUR red\nWIDTH 2\n"), "COLOUR");
  expect_rejected(edited("SIZE 4 4 4\n", ""), "SIZE");
  expect_rejected(edited("TYPE F F F\n", ""), "TYPE");
  expect_rejected(edited("FIELDS x y z\n", ""), "FIELDS");
  expect_rejected(edited("WIDTH 2\n", ""), "WIDTH");
  expect_rejected(edited("HEIGHT 1\n", ""), "HEIGHT");
  expect_rejected(edited("VERSION 0.7\n", ""), "VERSION");
  expect_rejected(kHeader, "DATA");
  expect_rejected(edited("WIDTH 2\n", "WIDTH 2\nWIDTH 2\n"), "WIDTH");
  expect_rejected(edited("VERSION 0.7", "VERSION 2.0"), "VERSION");
  expect_rejected(edited("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0 0 1"), "VIEWPOINT");
  expect_rejected(edited("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0 0 1 0 0 nan"), "VIEWPOINT");
  expect_rejected(edited("FIELDS x y z", "FIELDS x y x"), "FIELDS");
}

TEST(PcdReject, PointsMustEqualWidthTimesHeight) {
  expect_rejected(edited("POINTS 2", "POINTS 3"), "POINTS");
  expect_rejected(edited("HEIGHT 1", "HEIGHT 2"), "POINTS");
}

TEST(PcdReject, PerFieldLinesMustMatchFields) {
  expect_rejected(edited("SIZE 4 4 4", "SIZE 4 4"), "SIZE");
  expect_rejected(edited("TYPE F F F", "TYPE F F F F"), "TYPE");
  expect_rejected(edited("COUNT 1 1 1", "COUNT 1 1"), "COUNT");
}

TEST(PcdReject, InvalidTypeSizePairs) {
  for (const char* pair : {"SIZE 4 4 2\nTYPE F F F", "SIZE 4 4 1\nTYPE F F F", "SIZE 4 4 3\nTYPE F F I", "SIZE 4 4 16\nTYPE F F U",
                           "SIZE 4 4 4\nTYPE F F X", "SIZE 4 4 4\nTYPE F F FF"}) {
    expect_rejected(edited("SIZE 4 4 4\nTYPE F F F", pair), "TYPE");
  }
  expect_rejected(edited("SIZE 4 4 4", "SIZE 4 4 four"), "SIZE");
}

TEST(PcdReject, ZeroOrNegativeCounts) {
  expect_rejected(edited("COUNT 1 1 1", "COUNT 1 0 1"), "COUNT");
  expect_rejected(edited("COUNT 1 1 1", "COUNT 1 -1 1"), "COUNT");
  expect_rejected(edited("WIDTH 2", "WIDTH -2"), "WIDTH");
  expect_rejected(edited("HEIGHT 1\n", "HEIGHT 0\n"), "HEIGHT");
  expect_rejected(edited("POINTS 2", "POINTS -2"), "POINTS");
}

TEST(PcdReject, UnknownDataKind) { expect_rejected(edited("DATA ascii", "DATA binary_lz4"), "DATA"); }

TEST(PcdReject, BinaryDataShorterThanPromised) {
  expect_rejected(binary_file(23), "DATA");
  expect_rejected(binary_file(0), "DATA");
  EXPECT_EQ(parse_pcd(binary_file(30), "ok").table.num_points, 2u);  // trailing bytes (page padding) are fine
}

TEST(PcdReject, AsciiRowsAndValues) {
  expect_rejected(edited("4 5 6\n", ""), "DATA");                                 // fewer rows than POINTS
  expect_rejected(edited("4 5 6\n", "4 5\n"), "DATA");                            // short row
  expect_rejected(edited("4 5 6\n", "4 5 6 7\n"), "DATA");                        // long row
  expect_rejected(edited("4 5 6\n", "4 five 6\n"), "DATA");                       // not a number
  expect_rejected(edited("4 5 6\n", "4 5 1e39\n"), "DATA");                       // beyond float32
  EXPECT_EQ(parse_pcd(to_bytes(kAscii + "7 8 9\n"), "ok").table.num_points, 2u);  // extra rows ignored
  EXPECT_TRUE(std::isnan(parse_pcd(to_bytes(edited("4 5 6", "nan -inf +6")), "ok").table.fields[0].value(1)));
  const std::string ints = edited("SIZE 4 4 4\nTYPE F F F", "SIZE 4 4 1\nTYPE F F U");
  expect_rejected(edited("4 5 6", "4 5 256", ints), "DATA");  // beyond uint8
  expect_rejected(edited("4 5 6", "4 5 -1", ints), "DATA");   // negative unsigned
  expect_rejected(edited("4 5 6", "4 5 1.5", ints), "DATA");  // not an integer
  EXPECT_EQ(parse_pcd(to_bytes(edited("4 5 6", "4 5 255", ints)), "ok").table.fields[2].value(1), 255.0);
}

TEST(PcdReject, CompressedSizesThatLie) {
  const auto good = compressed_file();
  const std::size_t prefix = compressed_prefix_offset(good);
  std::uint32_t compressed_size = 0;
  std::memcpy(&compressed_size, good.data() + prefix, 4);

  auto beyond = good;
  set_u32(beyond, prefix, compressed_size + 1);
  expect_rejected(beyond, "DATA");
  auto wrong_total = good;
  set_u32(wrong_total, prefix + 4, 20);  // POINTS x record size = 24
  expect_rejected(wrong_total, "DATA");
  auto corrupt = good;
  set_u32(corrupt, prefix + 4, 24);
  corrupt[prefix + 8] = std::byte{0xff};  // a back reference before the start of the output
  expect_rejected(corrupt, "DATA");
  expect_rejected(std::vector<std::byte>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(prefix + 5)), "DATA");
  // A block too small to expand to the promised size is refused before allocating.
  const std::string huge = edited("WIDTH 2", "WIDTH 100000000", edited("POINTS 2", "POINTS 100000000"));
  auto bomb = to_bytes(huge.substr(0, huge.find("DATA")) + "DATA binary_compressed\n");
  const std::size_t at = bomb.size();
  bomb.resize(at + 12);
  set_u32(bomb, at, 4);
  set_u32(bomb, at + 4, 1200000000);
  expect_rejected(bomb, "DATA");
}

TEST(PcdReject, AbsurdSizesAreRefusedWithoutAllocating) {
  const std::string big = "POINTS 18446744073709551615";
  expect_rejected(edited("POINTS 2", big), "POINTS");
  const std::string wide = edited("WIDTH 2", "WIDTH 4294967295", edited("HEIGHT 1", "HEIGHT 4294967295"));
  expect_rejected(edited("POINTS 2", "POINTS 18446744065119617025", wide), "POINTS");  // 64-bit overflow with 12-byte records
  expect_rejected(edited("COUNT 1 1 1", "COUNT 1 1 4294967295", edited("POINTS 2\n", "", wide)), "POINTS");
  expect_rejected(edited("WIDTH 2", "WIDTH 4294967296"), "WIDTH");
  const std::string million = edited("WIDTH 2", "WIDTH 1000000000", edited("POINTS 2", "POINTS 1000000000"));
  expect_rejected(million, "DATA");  // ascii
  expect_rejected(binary_file(24, million.substr(0, million.find("DATA"))), "DATA");
}

// Where a real file's data ends (files may carry trailing page padding).
std::size_t data_end(const std::vector<std::byte>& bytes, const PcdCloud& cloud) {
  const std::string text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const std::string marker = std::string("DATA ") + pcd_encoding_name(cloud.encoding) + "\n";
  const std::size_t body = text.find(marker) + marker.size();
  if (cloud.encoding == PcdEncoding::kAscii) return bytes.size();
  if (cloud.encoding == PcdEncoding::kBinaryCompressed) {
    std::uint32_t compressed_size = 0;
    std::memcpy(&compressed_size, bytes.data() + body, 4);
    return body + 8 + compressed_size;
  }
  std::size_t record_size = 0;
  for (const auto& column : cloud.table.fields) record_size += column.stride();
  return body + cloud.table.num_points * record_size;
}

// Real files cut short: always InputError, never a crash.
TEST(PcdReject, TruncatedRealFiles) {
  MLIDAR_REQUIRE_SHARED_DATA();
  std::mt19937_64 rng(5);
  for (const char* name : {"opencalib_3lidar/0001/left.pcd", "opencalib_p64_qt/qt.pcd", "ramlab_wallcorner/raw/ref_filter.pcd",
                           "ramlab_wallcorner/plane/ref_plane_2.pcd", "scan_pair/251370668.pcd"}) {
    SCOPED_TRACE(name);
    const auto bytes = read_file_bytes(mlidar::test::shared_data() / "real" / name);
    const PcdCloud cloud = parse_pcd(bytes, name);
    // Cutting ascii anywhere in its first half loses rows; binary data must be whole.
    const std::size_t cut_max = cloud.encoding == PcdEncoding::kAscii ? bytes.size() / 2 : data_end(bytes, cloud) - 1;
    std::vector<std::size_t> cuts = {0, 10, 100, cut_max};
    std::uniform_int_distribution<std::size_t> anywhere(0, cut_max);
    for (int i = 0; i < 20; ++i) cuts.push_back(anywhere(rng));
    for (std::size_t cut : cuts) {
      const std::vector<std::byte> prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
      EXPECT_THROW(parse_pcd(prefix, name), InputError) << "cut at " << cut << " of " << bytes.size();
    }
    const std::vector<std::byte> whole(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(data_end(bytes, cloud)));
    EXPECT_EQ(parse_pcd(whole, name).table.num_points, cloud.table.num_points);
  }
}

}  // namespace
}  // namespace mlidar::io
