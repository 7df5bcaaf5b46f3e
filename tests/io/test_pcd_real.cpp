// Every PCD under shared/data/real read and checked against its own header
// text and the data README (counts, fields, types, plausible values).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "mlidar/io/file_bytes.hpp"
#include "test_pcd_support.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {

using mlidar::test::shared_data;

std::filesystem::path real(const std::string& relative) { return shared_data() / "real" / relative; }

// Independent oracle: the header lines as words, read with iostreams.
std::map<std::string, std::vector<std::string>> header_words(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::map<std::string, std::vector<std::string>> words;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream stream(line);
    std::string keyword;
    if (!(stream >> keyword) || keyword[0] == '#') continue;
    for (std::string word; stream >> word;) words[keyword].push_back(word);
    if (keyword == "DATA") break;
  }
  return words;
}

std::vector<std::filesystem::path> all_real_pcds() {
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(shared_data() / "real")) {
    if (entry.path().extension() == ".pcd") paths.push_back(entry.path());
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

void expect_fields(const PointTable& table, const std::vector<std::pair<std::string, ScalarType>>& expected) {
  ASSERT_EQ(table.fields.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(table.fields[i].name, expected[i].first);
    EXPECT_EQ(table.fields[i].type, expected[i].second) << expected[i].first;
  }
}

std::pair<double, double> value_range(const FieldColumn& column, std::size_t num_points) {
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < num_points; ++i) {
    lo = std::min(lo, column.value(i));
    hi = std::max(hi, column.value(i));
  }
  return {lo, hi};
}

constexpr ScalarType F32 = ScalarType::kF32;
constexpr ScalarType F64 = ScalarType::kF64;
constexpr ScalarType U16 = ScalarType::kU16;

TEST(PcdReal, EveryFileMatchesItsHeader) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto paths = all_real_pcds();
  EXPECT_EQ(paths.size(), 123u);  // README: 100 balm (full20..full119) + 9 opencalib + 2 p64/qt + 10 ramlab + 2 scan_pair
  for (const auto& path : paths) {
    SCOPED_TRACE(path.string());
    auto words = header_words(path);
    const PcdCloud cloud = read_pcd(path);
    const PointTable& table = cloud.table;
    EXPECT_EQ(std::to_string(table.num_points), words["POINTS"].at(0));
    EXPECT_EQ(std::to_string(table.width), words["WIDTH"].at(0));
    EXPECT_EQ(std::to_string(table.height), words["HEIGHT"].at(0));
    EXPECT_EQ(pcd_encoding_name(cloud.encoding), words["DATA"].at(0));
    ASSERT_EQ(table.fields.size(), words["FIELDS"].size());
    for (std::size_t f = 0; f < table.fields.size(); ++f) {
      const FieldColumn& column = table.fields[f];
      EXPECT_EQ(column.name, words["FIELDS"][f]);
      EXPECT_EQ(std::to_string(scalar_size(column.type)), words["SIZE"][f]);
      EXPECT_EQ(std::to_string(column.count), words["COUNT"][f]);
      EXPECT_EQ(column.data.size(), table.num_points * column.stride());
    }
    for (const char* axis : {"x", "y", "z"}) {  // LiDAR points: finite and within 500 m (full89.pcd has a return at 451 m)
      const auto [lo, hi] = value_range(*table.find(axis), table.num_points);
      EXPECT_GT(lo, -500.0) << axis;
      EXPECT_LT(hi, 500.0) << axis;
      EXPECT_LT(lo, hi) << axis;
    }
  }
}

TEST(PcdReal, OpenCalibThreeLidarsAreCompressedWith64Rings) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const PcdCloud top = read_pcd(real("opencalib_3lidar/0001/top.pcd"));
  EXPECT_EQ(top.encoding, PcdEncoding::kBinaryCompressed);
  EXPECT_EQ(top.table.num_points, 92677u);
  expect_fields(top.table, {{"x", F32}, {"y", F32}, {"z", F32}, {"intensity", F32}, {"ring", U16}, {"timestamp", F64}});
  const auto [ring_lo, ring_hi] = value_range(*top.table.find("ring"), top.table.num_points);
  EXPECT_EQ(ring_lo, 0.0);
  EXPECT_EQ(ring_hi, 63.0);
  const auto [i_lo, i_hi] = value_range(*top.table.find("intensity"), top.table.num_points);
  EXPECT_GE(i_lo, 0.0);
  EXPECT_LE(i_hi, 255.0);
  // Absolute unix seconds (2022-02-15), one ~0.1 s sweep.
  const auto [t_lo, t_hi] = value_range(*top.table.find("timestamp"), top.table.num_points);
  EXPECT_GT(t_lo, 1.6e9);
  EXPECT_GT(t_hi - t_lo, 0.05);
  EXPECT_LT(t_hi - t_lo, 0.2);
  for (const char* side : {"0001/left.pcd", "0001/right.pcd"}) {
    const PcdCloud cloud = read_pcd(real(std::string("opencalib_3lidar/") + side));
    EXPECT_GT(cloud.table.num_points, 8000u);
    EXPECT_LT(cloud.table.num_points, 11000u);
    EXPECT_LE(value_range(*cloud.table.find("ring"), cloud.table.num_points).second, 63.0);
  }
}

TEST(PcdReal, OpenCalibP64IsCompressedAndQtIsBinaryWithFloat64Time) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const PcdCloud p64 = read_pcd(real("opencalib_p64_qt/p64.pcd"));
  EXPECT_EQ(p64.encoding, PcdEncoding::kBinaryCompressed);
  EXPECT_EQ(p64.table.num_points, 77547u);
  expect_fields(p64.table, {{"x", F32}, {"y", F32}, {"z", F32}, {"intensity", F32}, {"ring", U16}, {"timestamp", F64}});
  const PcdCloud qt = read_pcd(real("opencalib_p64_qt/qt.pcd"));
  EXPECT_EQ(qt.encoding, PcdEncoding::kBinary);
  EXPECT_EQ(qt.table.num_points, 12414u);
  expect_fields(qt.table, {{"x", F32}, {"y", F32}, {"z", F32}, {"intensity", F32}, {"t", F64}});
  const auto [t_lo, t_hi] = value_range(*qt.table.find("t"), qt.table.num_points);
  EXPECT_GT(t_lo, 1.5e9);
  EXPECT_LT(t_hi - t_lo, 0.2);
}

TEST(PcdReal, RamlabPaddingFieldIsKeptAndRewritesTheFile) {
  MLIDAR_REQUIRE_SHARED_DATA();
  for (const char* name : {"raw/data_filter.pcd", "raw/ref_filter.pcd"}) {
    const auto path = real(std::string("ramlab_wallcorner/") + name);
    const PcdCloud cloud = read_pcd(path);
    expect_fields(cloud.table, {{"x", F32}, {"y", F32}, {"z", F32}, {"_", ScalarType::kU8}});
    const FieldColumn& padding = *cloud.table.find("_");
    EXPECT_EQ(padding.count, 4u);
    // PCL's PointXYZ pads with its homogeneous coordinate: float 1.0 in every point.
    const float one = 1.0f;
    for (std::size_t i = 0; i < cloud.table.num_points; ++i) {
      ASSERT_EQ(std::memcmp(padding.data.data() + 4 * i, &one, 4), 0) << "point " << i;
    }
    // Re-encoding reproduces the file up to its trailing page padding.
    const auto original = read_file_bytes(path);
    const auto encoded = encode_pcd(cloud);
    ASSERT_LE(encoded.size(), original.size());
    EXPECT_TRUE(std::equal(encoded.begin(), encoded.end(), original.begin()));
  }
}

TEST(PcdReal, RamlabAsciiPlaneCropsAreTheUnionOfPlanes) {
  MLIDAR_REQUIRE_SHARED_DATA();
  for (const std::string lidar : {"data", "ref"}) {
    const PcdCloud all = read_pcd(real("ramlab_wallcorner/plane/" + lidar + "_planes.pcd"));
    EXPECT_EQ(all.encoding, PcdEncoding::kAscii);
    expect_fields(all.table, {{"x", F32}, {"y", F32}, {"z", F32}, {"intensity", F32}});
    std::size_t offset = 0;
    for (int plane = 1; plane <= 3; ++plane) {
      const PcdCloud part = read_pcd(real("ramlab_wallcorner/plane/" + lidar + "_plane_" + std::to_string(plane) + ".pcd"));
      expect_fields(part.table, {{"x", F32}, {"y", F32}, {"z", F32}});
      for (std::size_t f = 0; f < 3; ++f) {  // x y z of the union, in plane order
        const auto& whole = all.table.fields[f].data;
        const auto& piece = part.table.fields[f].data;
        ASSERT_LE(offset * 4 + piece.size(), whole.size());
        EXPECT_TRUE(std::equal(piece.begin(), piece.end(), whole.begin() + static_cast<std::ptrdiff_t>(offset * 4)));
      }
      offset += part.table.num_points;
    }
    EXPECT_EQ(offset, all.table.num_points);
  }
  // The first row of data_planes.pcd is "12.880256 1.3219556 -0.23224582 0".
  const PcdCloud all = read_pcd(real("ramlab_wallcorner/plane/data_planes.pcd"));
  EXPECT_EQ(all.table.fields[0].value(0), static_cast<double>(12.880256f));
  EXPECT_EQ(all.table.fields[1].value(0), static_cast<double>(1.3219556f));
  EXPECT_EQ(all.table.fields[2].value(0), static_cast<double>(-0.23224582f));
}

TEST(PcdReal, BalmOusterFramesHaveEightFloatFieldsAndZeroNormals) {
  MLIDAR_REQUIRE_SHARED_DATA();
  for (int frame = 20; frame <= 49; ++frame) {
    const PcdCloud cloud = read_pcd(real("balm_ouster/frames/full" + std::to_string(frame) + ".pcd"));
    SCOPED_TRACE(frame);
    EXPECT_EQ(cloud.encoding, PcdEncoding::kBinary);
    expect_fields(cloud.table, {{"x", F32},
                                {"y", F32},
                                {"z", F32},
                                {"intensity", F32},
                                {"normal_x", F32},
                                {"normal_y", F32},
                                {"normal_z", F32},
                                {"curvature", F32}});
    EXPECT_GT(cloud.table.num_points, 50000u);
    EXPECT_LT(cloud.table.num_points, 100000u);
    for (const char* zero : {"normal_x", "normal_y", "normal_z", "curvature"}) {
      EXPECT_EQ(value_range(*cloud.table.find(zero), cloud.table.num_points), std::make_pair(0.0, 0.0)) << zero;
    }
  }
}

TEST(PcdReal, ScanPairHasIntensity) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const std::map<std::string, std::size_t> expected = {{"251370668.pcd", 69088}, {"251371071.pcd", 69792}};
  for (const auto& [name, points] : expected) {
    const PcdCloud cloud = read_pcd(real("scan_pair/" + name));
    EXPECT_EQ(cloud.table.num_points, points);
    expect_fields(cloud.table, {{"x", F32}, {"y", F32}, {"z", F32}, {"intensity", F32}});
  }
}

TEST(PcdReal, ToScanMapsFloat64TimesToSecondsWithinOneSweep) {
  MLIDAR_REQUIRE_SHARED_DATA();
  for (const char* name : {"opencalib_3lidar/0001/top.pcd", "opencalib_p64_qt/p64.pcd", "opencalib_p64_qt/qt.pcd"}) {
    SCOPED_TRACE(name);
    const PcdCloud cloud = read_pcd(real(name));
    const Scan scan = to_scan(cloud.table, name);
    ASSERT_EQ(scan.size(), cloud.table.num_points);
    ASSERT_TRUE(scan.has_time());
    const auto [lo, hi] = std::minmax_element(scan.time.begin(), scan.time.end());
    EXPECT_EQ(*lo, 0.0f);
    EXPECT_GT(*hi, 0.0f);
    EXPECT_LT(*hi, 0.2f);
    EXPECT_GT(scan.stamp, 1.5e9);  // the absolute start is kept as the stamp
    EXPECT_LT(scan.stamp, 1.7e9);
  }
}

}  // namespace
}  // namespace mlidar::io
