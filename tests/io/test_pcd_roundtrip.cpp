// write -> read gives back the same columns, bit for bit, in every encoding.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <liblzf/lzf.h>

#include "mlidar/io/file_bytes.hpp"
#include "test_pcd_support.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {

using test::expect_same_table;

constexpr PcdEncoding kEncodings[] = {PcdEncoding::kAscii, PcdEncoding::kBinary, PcdEncoding::kBinaryCompressed};

template <typename T>
void fill_random_integers(FieldColumn& column, std::mt19937_64& rng) {
  std::uniform_int_distribution<std::uint64_t> bits;
  for (std::size_t offset = 0; offset < column.data.size(); offset += sizeof(T)) {
    const auto value = static_cast<T>(bits(rng));  // every bit pattern is a valid integer
    std::memcpy(column.data.data() + offset, &value, sizeof(T));
  }
}

// Ordinary values plus the awkward ones: NaN, infinities, -0, subnormals, extremes.
template <typename T>
void fill_floats(FieldColumn& column, std::mt19937_64& rng) {
  using Limits = std::numeric_limits<T>;
  const T specials[] = {Limits::quiet_NaN(), Limits::infinity(), -Limits::infinity(), T(-0.0), Limits::denorm_min(),
                        Limits::min(),       Limits::max(),      Limits::lowest(),    T(0.1),  T(1) / T(3)};
  std::uniform_real_distribution<T> uniform(T(-200), T(200));
  std::size_t index = 0;
  for (std::size_t offset = 0; offset < column.data.size(); offset += sizeof(T), ++index) {
    const T value = index < std::size(specials) ? specials[index] : uniform(rng) * std::pow(T(10), T(index % 7) - T(3));
    std::memcpy(column.data.data() + offset, &value, sizeof(T));
  }
}

void fill(FieldColumn& column, std::mt19937_64& rng) {
  switch (column.type) {
    case ScalarType::kI8:
      return fill_random_integers<std::int8_t>(column, rng);
    case ScalarType::kU8:
      return fill_random_integers<std::uint8_t>(column, rng);
    case ScalarType::kI16:
      return fill_random_integers<std::int16_t>(column, rng);
    case ScalarType::kU16:
      return fill_random_integers<std::uint16_t>(column, rng);
    case ScalarType::kI32:
      return fill_random_integers<std::int32_t>(column, rng);
    case ScalarType::kU32:
      return fill_random_integers<std::uint32_t>(column, rng);
    case ScalarType::kI64:
      return fill_random_integers<std::int64_t>(column, rng);
    case ScalarType::kU64:
      return fill_random_integers<std::uint64_t>(column, rng);
    case ScalarType::kF32:
      return fill_floats<float>(column, rng);
    case ScalarType::kF64:
      return fill_floats<double>(column, rng);
  }
}

// An organised 7 x 3 cloud with every scalar type, COUNT > 1, two padding
// fields and NaN points (x, y, z start with NaN and inf from fill_floats).
PcdCloud every_type_cloud(PcdEncoding encoding, std::uint64_t seed) {
  PcdCloud cloud;
  cloud.encoding = encoding;
  cloud.viewpoint = {1.5, -2.25, 0.1, 0.5, 0.5, -0.5, 0.5};
  PointTable& table = cloud.table;
  table.width = 7;
  table.height = 3;
  table.num_points = 21;
  std::mt19937_64 rng(seed);
  const ScalarType all[] = {ScalarType::kI8,  ScalarType::kU8,  ScalarType::kI16, ScalarType::kU16, ScalarType::kI32,
                            ScalarType::kU32, ScalarType::kI64, ScalarType::kU64, ScalarType::kF32, ScalarType::kF64};
  for (const char* axis : {"x", "y", "z"}) fill(table.add_field(axis, ScalarType::kF32), rng);
  fill(table.add_field("_", ScalarType::kU8, 4), rng);
  for (ScalarType type : all) {
    fill(table.add_field(std::string("v_") + scalar_name(type), type), rng);
    fill(table.add_field(std::string("a_") + scalar_name(type), type, 3), rng);
  }
  fill(table.add_field("_", ScalarType::kU8, 2), rng);
  return cloud;
}

// PCL leaves padding out of binary_compressed blocks, so it reads back as zeros there.
PointTable expected_after_round_trip(PointTable table, PcdEncoding encoding) {
  if (encoding != PcdEncoding::kBinaryCompressed) return table;
  for (FieldColumn& column : table.fields) {
    if (column.name == "_") std::fill(column.data.begin(), column.data.end(), std::byte{0});
  }
  return table;
}

TEST(PcdRoundTrip, EveryTypeCountPaddingNanAndOrganisedCloudInEveryEncoding) {
  for (PcdEncoding encoding : kEncodings) {
    SCOPED_TRACE(pcd_encoding_name(encoding));
    const PcdCloud cloud = every_type_cloud(encoding, 42);
    const PcdCloud back = parse_pcd(encode_pcd(cloud), "memory");
    EXPECT_EQ(back.encoding, encoding);
    EXPECT_EQ(back.version, "0.7");
    EXPECT_EQ(back.viewpoint, cloud.viewpoint);
    EXPECT_EQ(back.table.width, 7u);
    EXPECT_EQ(back.table.height, 3u);
    expect_same_table(expected_after_round_trip(cloud.table, encoding), back.table);
    EXPECT_TRUE(std::isnan(back.table.find("x")->value(0)));
  }
}

TEST(PcdRoundTrip, BinaryKeepsPaddingBytes) {
  const PcdCloud cloud = every_type_cloud(PcdEncoding::kBinary, 7);
  const PcdCloud back = parse_pcd(encode_pcd(cloud), "memory");
  EXPECT_TRUE(back.table.fields[3].data == cloud.table.fields[3].data);
  EXPECT_NE(std::count(back.table.fields[3].data.begin(), back.table.fields[3].data.end(), std::byte{0}),
            static_cast<std::ptrdiff_t>(back.table.fields[3].data.size()));
}

TEST(PcdRoundTrip, WriteAndReadFilesInEveryEncoding) {
  const auto dir = mlidar::test::scratch_dir();
  for (PcdEncoding encoding : kEncodings) {
    const PcdCloud cloud = every_type_cloud(encoding, 3);
    const auto path = dir / (std::string(pcd_encoding_name(encoding)) + ".pcd");
    write_pcd(path, cloud);
    expect_same_table(expected_after_round_trip(cloud.table, encoding), read_pcd(path).table);
    EXPECT_TRUE(read_file_bytes(path) == encode_pcd(cloud));
  }
}

// PCL leaves padding columns out of the LZF block; a block holding them is read too.
TEST(PcdRoundTrip, CompressedBlockWithPaddingColumnsKeepsThem) {
  PcdCloud cloud = every_type_cloud(PcdEncoding::kBinaryCompressed, 9);
  std::vector<std::byte> block;
  for (const FieldColumn& column : cloud.table.fields) block.insert(block.end(), column.data.begin(), column.data.end());
  std::vector<std::byte> compressed(block.size() * 2 + 64);
  const unsigned int compressed_size =
      lzf_compress(block.data(), static_cast<unsigned int>(block.size()), compressed.data(), static_cast<unsigned int>(compressed.size()));
  ASSERT_GT(compressed_size, 0u);
  const std::vector<std::byte> pcl_style = encode_pcd(cloud);
  const std::string marker = "DATA binary_compressed\n";
  const std::string text(reinterpret_cast<const char*>(pcl_style.data()), pcl_style.size());
  std::vector<std::byte> file(pcl_style.begin(), pcl_style.begin() + static_cast<std::ptrdiff_t>(text.find(marker) + marker.size()));
  const std::uint32_t sizes[2] = {compressed_size, static_cast<std::uint32_t>(block.size())};
  const auto* size_bytes = reinterpret_cast<const std::byte*>(sizes);
  file.insert(file.end(), size_bytes, size_bytes + sizeof(sizes));
  file.insert(file.end(), compressed.begin(), compressed.begin() + compressed_size);
  expect_same_table(cloud.table, parse_pcd(file, "memory").table);
}

TEST(PcdRoundTrip, EmptyCloudInEveryEncoding) {
  for (PcdEncoding encoding : kEncodings) {
    PcdCloud cloud;
    cloud.encoding = encoding;
    for (const char* axis : {"x", "y", "z"}) cloud.table.add_field(axis, ScalarType::kF32);
    const PcdCloud back = parse_pcd(encode_pcd(cloud), "memory");
    EXPECT_EQ(back.table.num_points, 0u);
    EXPECT_EQ(back.table.fields.size(), 3u);
  }
}

TEST(PcdRoundTrip, ScanSurvivesEveryEncoding) {
  Scan scan;
  for (int i = 0; i < 100; ++i) {
    scan.points.emplace_back(0.37f * static_cast<float>(i), -1.1f * static_cast<float>(i), 1e-3f * static_cast<float>(i * i));
    scan.intensity.push_back(static_cast<float>(i % 17));
    scan.ring.push_back(static_cast<std::uint16_t>(i % 64));
    scan.time.push_back(1e-3f * static_cast<float>(i));
  }
  for (PcdEncoding encoding : kEncodings) {
    PcdCloud cloud;
    cloud.encoding = encoding;
    cloud.table = from_scan(scan);
    const Scan back = to_scan(parse_pcd(encode_pcd(cloud), "memory").table, "memory");
    EXPECT_EQ(back.points, scan.points);
    EXPECT_EQ(back.intensity, scan.intensity);
    EXPECT_EQ(back.ring, scan.ring);
    EXPECT_EQ(back.time, scan.time);
  }
}

TEST(PcdRoundTrip, DropNanRemovesNonFinitePointsAndFlattens) {
  PcdCloud cloud = every_type_cloud(PcdEncoding::kBinary, 11);
  const PointTable& table = cloud.table;
  std::vector<std::size_t> finite;
  for (std::size_t i = 0; i < table.num_points; ++i) {
    if (std::isfinite(table.find("x")->value(i)) && std::isfinite(table.find("y")->value(i)) && std::isfinite(table.find("z")->value(i))) {
      finite.push_back(i);
    }
  }
  ASSERT_LT(finite.size(), table.num_points);  // the fill puts NaN and inf first
  ASSERT_GT(finite.size(), 0u);
  const PcdCloud back = parse_pcd(encode_pcd(cloud), "memory", {.drop_nan = true});
  EXPECT_EQ(back.table.num_points, finite.size());
  EXPECT_EQ(back.table.width, finite.size());
  EXPECT_EQ(back.table.height, 1u);
  for (std::size_t f = 0; f < table.fields.size(); ++f) {
    const FieldColumn& column = table.fields[f];
    const std::size_t stride = column.stride();
    ASSERT_EQ(back.table.fields[f].data.size(), finite.size() * stride);
    for (std::size_t j = 0; j < finite.size(); ++j) {
      EXPECT_EQ(std::memcmp(back.table.fields[f].data.data() + j * stride, column.data.data() + finite[j] * stride, stride), 0);
    }
  }
}

TEST(PcdRoundTrip, RealCompressedFileSurvivesBinaryAndBack) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto path = mlidar::test::shared_data() / "real/opencalib_3lidar/0001/top.pcd";
  const PcdCloud original = read_pcd(path);
  for (PcdEncoding encoding : kEncodings) {
    PcdCloud cloud = original;
    cloud.encoding = encoding;
    const PcdCloud again = parse_pcd(encode_pcd(cloud), "memory");
    expect_same_table(original.table, again.table);
    // ... and back to binary_compressed once more.
    PcdCloud recompressed = again;
    recompressed.encoding = PcdEncoding::kBinaryCompressed;
    expect_same_table(original.table, parse_pcd(encode_pcd(recompressed), "memory").table);
  }
}

TEST(PcdRoundTrip, EncodingRejectsInconsistentTables) {
  PcdCloud cloud;
  cloud.table.num_points = 4;
  cloud.table.add_field("x", ScalarType::kF32).data.resize(3);  // one byte short
  EXPECT_THROW(encode_pcd(cloud), std::invalid_argument);
  cloud.table.fields[0].data.resize(16);
  cloud.table.width = 3;
  cloud.table.height = 2;  // 6 != 4 points
  EXPECT_THROW(encode_pcd(cloud), std::invalid_argument);
  cloud.table.height = 1;
  cloud.table.fields[0].name = "has space";
  EXPECT_THROW(encode_pcd(cloud), std::invalid_argument);
  cloud.table.fields[0].name = "x";
  EXPECT_NO_THROW(encode_pcd(cloud));
  cloud.table.fields.push_back(cloud.table.fields[0]);  // a second x
  EXPECT_THROW(encode_pcd(cloud), std::invalid_argument);
}

TEST(PcdRoundTrip, EncodingNames) {
  EXPECT_STREQ(pcd_encoding_name(PcdEncoding::kAscii), "ascii");
  EXPECT_STREQ(pcd_encoding_name(PcdEncoding::kBinary), "binary");
  EXPECT_STREQ(pcd_encoding_name(PcdEncoding::kBinaryCompressed), "binary_compressed");
}

}  // namespace
}  // namespace mlidar::io
