// End-to-end checks of the mlidar executable: every real cloud is described,
// conversions keep fields, bad input exits 3 and leaves nothing behind.
#include <cctype>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

struct RealCloud {
  const char* path;    // under shared/data/real
  std::size_t points;  // from the header / file size
  const char* format;
};

const RealCloud kRealClouds[] = {
    {"opencalib_3lidar/0001/top.pcd", 92677, "pcd"},
    {"opencalib_3lidar/0001/left.pcd", 8572, "pcd"},
    {"opencalib_3lidar/0002/right-2022-02-15-17-36-04-445.pcd", 9487, "pcd"},
    {"opencalib_3lidar/0003/top-2022-02-15-17-45-07-750.pcd", 87937, "pcd"},
    {"opencalib_p64_qt/p64.pcd", 77547, "pcd"},
    {"opencalib_p64_qt/qt.pcd", 12414, "pcd"},
    {"balm_ouster/frames/full20.pcd", 73082, "pcd"},
    {"balm_ouster/frames/full49.pcd", 84855, "pcd"},
    {"ramlab_wallcorner/raw/ref_filter.pcd", 7013, "pcd"},
    {"ramlab_wallcorner/raw/data_filter.pcd", 8101, "pcd"},
    {"ramlab_wallcorner/plane/data_planes.pcd", 7031, "pcd"},
    {"ramlab_wallcorner/plane/ref_plane_2.pcd", 690, "pcd"},
    {"scan_pair/251370668.pcd", 69088, "pcd"},
    {"scan_pair/251371071.pcd", 69792, "pcd"},
    {"scan_pair/source.ply", 69792, "ply"},
    {"scan_pair/target.ply", 69088, "ply"},
    {"kitti_object/training/velodyne/000000.bin", 1846144 / 16, "kitti-bin"},
    {"kitti_object/training/velodyne/000002.bin", 2030256 / 16, "kitti-bin"},
    {"kitti_000008/000008_velodyne_reduced.bin", 275808 / 16, "kitti-bin"},
    {"nuscenes_keyframe/n015-2018-07-24-11-22-45+0800__LIDAR_TOP__1532402927647951.pcd.bin", 693760 / 20, "kitti-bin"},
};

class InfoOnRealData : public ::testing::TestWithParam<RealCloud> {};

TEST_P(InfoOnRealData, ReportsPointCountAndBounds) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const RealCloud& cloud = GetParam();
  const fs::path path = shared_data() / "real" / cloud.path;
  const CliResult result = run_cli("info --json " + quoted(path.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(result.output);
  EXPECT_EQ(json["points"].get<std::size_t>(), cloud.points);
  EXPECT_EQ(json["format"].get<std::string>(), cloud.format);
  ASSERT_TRUE(json.contains("bounds"));
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LT(json["bounds"]["min"][axis].get<double>(), json["bounds"]["max"][axis].get<double>());
    EXPECT_LT(std::abs(json["bounds"]["max"][axis].get<double>()), 500.0);  // LiDAR ranges, not garbage
  }
}

std::string cloud_test_name(const ::testing::TestParamInfo<RealCloud>& info) {
  std::string name = std::to_string(info.index) + "_" + fs::path(info.param.path).stem().string();
  for (char& c : name) {
    if (std::isalnum(static_cast<unsigned char>(c)) == 0) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Cli, InfoOnRealData, ::testing::ValuesIn(kRealClouds), cloud_test_name);

TEST(CliInfo, OpenCalibTopHasRingsAndSweepTime) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto result = run_cli("info --json " + quoted((shared_data() / "real/opencalib_3lidar/0001/top.pcd").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(result.output);
  EXPECT_EQ(json["rings"]["count"].get<int>(), 64);
  EXPECT_GT(json["time"]["span_s"].get<double>(), 0.0);
  EXPECT_LT(json["time"]["span_s"].get<double>(), 0.2);  // one sweep of a 10 Hz LiDAR
  EXPECT_EQ(json["encoding"].get<std::string>(), "binary_compressed");
}

TEST(CliInfo, PrintsTextForSeveralFiles) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path real = shared_data() / "real";
  const auto result = run_cli("info " + quoted((real / "scan_pair/source.ply").string()) + " " +
                              quoted((real / "ramlab_wallcorner/raw/ref_filter.pcd").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("points    69792"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("_:uint8x4"), std::string::npos) << result.output;
}

TEST(CliInfo, MissingFileIsBadInput) {
  const auto result = run_cli("info /nonexistent/cloud.pcd");
  EXPECT_EQ(result.exit_code, 3);
  EXPECT_NE(result.output.find("/nonexistent/cloud.pcd"), std::string::npos) << result.output;
}

TEST(CliInfo, TruncatedFileIsBadInputNamingTheFile) {
  const fs::path dir = scratch_dir();
  const fs::path file = dir / "short.pcd";
  std::ofstream(file) << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 10\nHEIGHT 1\n"
                         "POINTS 10\nDATA binary\n1234";
  const auto result = run_cli("info " + quoted(file.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("short.pcd"), std::string::npos) << result.output;
}

TEST(CliUsage, UnknownCommandAndMissingArgumentsAreUsageErrors) {
  EXPECT_EQ(run_cli("").exit_code, 2);
  EXPECT_EQ(run_cli("frobnicate").exit_code, 2);
  EXPECT_EQ(run_cli("convert only_one.pcd").exit_code, 2);
  const auto help = run_cli("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("3    bad input data or configuration file"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("130  interrupted (SIGINT), 143 terminated (SIGTERM)"), std::string::npos) << help.output;
}

TEST(CliConvert, PcdToPlyToPcdKeepsEveryField) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const fs::path input = shared_data() / "real/opencalib_3lidar/0001/left.pcd";
  ASSERT_EQ(run_cli("convert " + quoted(input.string()) + " " + quoted((dir / "a.ply").string())).exit_code, 0);
  const auto result =
      run_cli("convert " + quoted((dir / "a.ply").string()) + " " + quoted((dir / "b.pcd").string()) + " --encoding binary_compressed");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const io::CloudFile original = io::read_cloud(input);
  const io::CloudFile back = io::read_cloud(dir / "b.pcd");
  ASSERT_EQ(back.table.num_points, original.table.num_points);
  ASSERT_EQ(back.table.fields.size(), original.table.fields.size());
  for (std::size_t f = 0; f < original.table.fields.size(); ++f) {
    EXPECT_EQ(back.table.fields[f].name, original.table.fields[f].name);
    EXPECT_EQ(back.table.fields[f].type, original.table.fields[f].type);
    EXPECT_EQ(back.table.fields[f].data, original.table.fields[f].data) << original.table.fields[f].name;
  }
}

TEST(CliConvert, ToKittiBinKeepsXyzAndIntensity) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const fs::path input = shared_data() / "real/scan_pair/source.ply";
  ASSERT_EQ(run_cli("convert " + quoted(input.string()) + " " + quoted((dir / "s.bin").string())).exit_code, 0);
  const io::CloudFile bin = io::read_cloud(dir / "s.bin");
  const io::CloudFile ply = io::read_cloud(input);
  ASSERT_EQ(bin.table.num_points, ply.table.num_points);
  EXPECT_EQ(bin.table.find("x")->data, ply.table.find("x")->data);
  EXPECT_EQ(fs::file_size(dir / "s.bin"), ply.table.num_points * 16);
}

TEST(CliConvert, FailedConversionLeavesNoOutput) {
  const fs::path dir = scratch_dir();
  const fs::path bad = dir / "bad.ply";
  std::ofstream(bad) << "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\n"
                        "property float y\nproperty float z\nend_header\nxx";
  const auto result = run_cli("convert " + quoted(bad.string()) + " " + quoted((dir / "out.pcd").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("bad.ply"), std::string::npos) << result.output;
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1u) << "only the bad input may remain";
}

TEST(CliConvert, UnknownOutputExtensionIsUsageError) {
  const fs::path dir = scratch_dir();
  const auto result = run_cli("convert in.pcd " + quoted((dir / "out.xyz").string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;
}

TEST(CliConvert, UnwritableOutputFolderIsReportedAndLeavesNothing) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto result = run_cli("convert " + quoted((shared_data() / "real/scan_pair/source.ply").string()) + " /nonexistent_dir/out.pcd");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("/nonexistent_dir/out.pcd"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace mlidar::test
