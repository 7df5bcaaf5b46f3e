// `mlidar bag info|export` and --bag on the jobs, against the fixtures of
// tests/data/bags (written by python3-rosbag, npm @mcap/core and Python
// sqlite3), bags converted from datasets by tests/data/bags/dataset_to_bags.py
// (Debian's python3-rosbag and friends), and broken bags written by hand.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/bag_writer.hpp"
#include "apps/reliability_support.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "pose_error.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

const fs::path kBags = fs::path(MLIDAR_SOURCE_DIR) / "tests" / "data" / "bags";
const std::string kTopics = " --topics /top/points:top,/left/points:left,/right/points:right";

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(CliBag, InfoListsTopicsRatesFieldsAndTimeConventions) {
  const CliResult r = run_cli("bag info --json " + quoted((kBags / "mcap_zstd.mcap").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json info = nlohmann::json::parse(r.output);
  EXPECT_EQ(info["format"], "mcap");
  EXPECT_EQ(info["messages"], 251);
  std::map<std::string, nlohmann::json> topics;
  for (const auto& t : info["topics"]) topics[t["name"]] = t;
  EXPECT_EQ(topics["/top/points"]["count"], 20);
  EXPECT_NEAR(topics["/top/points"]["rate_hz"].get<double>(), 10.0, 1e-6);
  EXPECT_EQ(topics["/top/points"]["time"]["stamp_at"], "end");  // Velodyne: negative offsets
  EXPECT_EQ(topics["/left/points"]["time"]["unit"], "ns");      // Ouster: uint32 ns from the start
  EXPECT_EQ(topics["/left/points"]["time"]["stamp_at"], "start");
  EXPECT_EQ(topics["/right/points"]["time"]["reference"], "absolute");  // Hesai
  EXPECT_EQ(topics["/left/points"]["points"], 288);
  EXPECT_TRUE(topics["/left/points"]["organized"].get<bool>());
  EXPECT_EQ(topics["/imu"]["count"], 200);
  const CliResult cut = run_cli("bag info --json " + quoted((kBags / "ros1_truncated.bag").string()));
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  EXPECT_NE(nlohmann::json::parse(cut.output)["truncated"].get<std::string>().find("cut short"), std::string::npos);
}

TEST(CliBag, ABagCutShortIsReadToItsLastWholeMessageAndSaysSo) {
  const fs::path dir = scratch_dir();
  const CliResult r = run_cli("bag export " + quoted((kBags / "ros1_truncated.bag").string()) + kTopics + " --out " + quoted((dir / "out").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // expected.json: the whole messages are the first 10 /top/points (the frames), 11 /left/points and 6 /right/points.
  EXPECT_TRUE(fs::exists(dir / "out/scans/top/000009.pcd"));
  EXPECT_FALSE(fs::exists(dir / "out/scans/top/000010.pcd"));
  const CliResult odometry = run_cli("odometry --bag " + quoted((kBags / "ros1_truncated.bag").string()) + kTopics + " --out " + quoted((dir / "run").string()));
  EXPECT_NE(odometry.output.find("cut short; read up to its last whole message"), std::string::npos) << odometry.output;
  EXPECT_NE(odometry.output.find("right: 5 of 10 frames without a usable scan"), std::string::npos) << odometry.output;  // 5 Hz against 10 Hz
}

TEST(CliBag, ExportedFolderGivesTheSameOdometryAsTheBagBitForBit) {
  const fs::path dir = scratch_dir();
  for (const char* bag : {"ros1_lz4.bag", "mcap_zstd.mcap", "rosbag2_db3"}) {
    SCOPED_TRACE(bag);
    const std::string path = quoted((kBags / bag).string());
    const fs::path exported = dir / (std::string(bag) + ".dataset");
    CliResult r = run_cli("bag export " + path + kTopics + " --out " + quoted(exported.string()));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(fs::exists(exported / "scans/left/000019.pcd"));
    run_cli("odometry --threads 1 --dataset " + quoted(exported.string()) + " --out " + quoted((dir / "from_folder").string()));
    run_cli("odometry --threads 1 --bag " + path + kTopics + " --out " + quoted((dir / "from_bag").string()));
    for (const char* file : {"trajectory.tum", "map.ply"}) {
      const std::string a = read_text(dir / "from_folder" / file), b = read_text(dir / "from_bag" / file);
      EXPECT_FALSE(a.empty()) << file;
      EXPECT_EQ(a, b) << file;
    }
  }
}

TEST(CliBag, EveryFormatOfASimulatedDatasetGivesTheDatasetsSlam) {
  if (run_shell("/usr/bin/python3 -c 'import rosbag, yaml, zstandard'").exit_code != 0)
    GTEST_SKIP() << "Debian's python3-rosbag, python3-yaml and python3-zstandard are needed to write the bags "
                    "(scripts/install_deps.sh installs them)";
  const fs::path dir = scratch_dir();
  const fs::path bags = dir / "bags";
  const CliResult converted = run_shell("/usr/bin/python3 " + quoted((kBags / "dataset_to_bags.py").string()) + " " +
                                        quoted(small_dataset().string()) + " " + quoted(bags.string()));
  ASSERT_EQ(converted.exit_code, 0) << converted.output;
  const std::string models = " --models " + quoted((small_dataset() / "dataset.yaml").string());
  ASSERT_EQ(run_cli("slam --calibrate fixed --threads 1 --dataset " + quoted(small_dataset().string()) + " --out " +
                    quoted((dir / "folder").string()))
                .exit_code,
            0);
  const Trajectory reference = io::read_tum(dir / "folder" / "trajectory.tum");
  for (const char* bag : {"dataset.bag", "dataset.mcap", "dataset_db3"}) {
    SCOPED_TRACE(bag);
    const CliResult r = run_cli("slam --calibrate fixed --threads 1 --bag " + quoted((bags / bag).string()) +
                                " --topics /left/points:left,/right/points:right" + models + " --out " + quoted((dir / bag).string()));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Trajectory est = io::read_tum(dir / bag / "trajectory.tum");
    ASSERT_EQ(est.size(), reference.size());
    for (std::size_t k = 0; k < est.size(); ++k) {
      EXPECT_LT(translation_error_m(est.poses[k].T_world_base, reference.poses[k].T_world_base), 1e-9) << k;
      EXPECT_NEAR(est.poses[k].stamp, reference.poses[k].stamp, 1e-9) << k;
    }
  }
}

TEST(CliBag, ABagOfRealKeyframesGivesTheOdometryOfTheirFolder) {
  MLIDAR_REQUIRE_SHARED_DATA();
  if (run_shell("/usr/bin/python3 -c 'import rosbag, yaml'").exit_code != 0)
    GTEST_SKIP() << "Debian's python3-rosbag and python3-yaml are needed to write the bag (scripts/install_deps.sh installs them)";
  // BALM's Ouster keyframes full20..full25 (0.5 s apart, no ring, no time field) as a dataset, then as a ROS 1 bag.
  const fs::path dir = scratch_dir();
  const fs::path data = dir / "balm";
  fs::create_directories(data / "scans" / "ouster");
  std::ofstream times(data / "times.txt");
  for (int k = 0; k < 6; ++k) {
    fs::copy_file(shared_data() / "real/balm_ouster/frames" / ("full" + std::to_string(20 + k) + ".pcd"),
                  data / "scans/ouster" / ("00000" + std::to_string(k) + ".pcd"));
    times << 0.5 * k << '\n';
  }
  times.close();
  std::ofstream(data / "dataset.yaml")
      << "name: balm\nframe_period: 0.5\nbase: ouster\nlidars:\n  - {name: ouster, model: unknown, scans: scans/ouster}\n";
  ASSERT_EQ(run_shell("/usr/bin/python3 " + quoted((kBags / "dataset_to_bags.py").string()) + " " + quoted(data.string()) + " " +
                      quoted((dir / "bags").string()) + " --formats ros1")
                .exit_code,
            0);
  ASSERT_EQ(run_cli("odometry --threads 1 --period 0.5 --scans " + quoted((data / "scans/ouster").string()) + " --out " +
                    quoted((dir / "scans_run").string()))
                .exit_code,
            0);
  ASSERT_EQ(run_cli("odometry --threads 1 --bag " + quoted((dir / "bags/dataset.bag").string()) + " --topics /ouster/points:ouster --out " +
                    quoted((dir / "bag_run").string()))
                .exit_code,
            0);
  for (const char* file : {"trajectory.tum", "map.ply"})
    EXPECT_EQ(read_text(dir / "scans_run" / file), read_text(dir / "bag_run" / file)) << file;
}

struct BrokenBag {
  std::string name;
  std::vector<std::string> messages;
  std::string compression;
  std::uint32_t claimed_size;
  std::string expected;  ///< the message must hold this
};

class CliBrokenBag : public ::testing::TestWithParam<BrokenBag> {};

void PrintTo(const BrokenBag& bag, std::ostream* out) { *out << bag.name; }

TEST_P(CliBrokenBag, IsExitThreeNamingFileTopicAndMessageAndWritesNothing) {
  const BrokenBag& broken = GetParam();
  const fs::path dir = scratch_dir();
  const fs::path bag = dir / "broken.bag";
  write_bag(bag.string(), broken.messages, broken.compression, broken.claimed_size);
  for (const std::string command : {"odometry", "bag export"}) {
    const std::string input = command == "odometry" ? " --bag " + quoted(bag.string()) : " " + quoted(bag.string());
    const CliResult r = run_cli(command + input + " --topics /pts:a --out " + quoted((dir / "out").string()));
    EXPECT_EQ(r.exit_code, 3) << command << r.output;
    EXPECT_NE(r.output.find(bag.string()), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(broken.expected), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
}

const std::vector<RosField> kXyz = {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}};

INSTANTIATE_TEST_SUITE_P(
    Bags, CliBrokenBag,
    ::testing::Values(
        BrokenBag{"short_data",
                  {pointcloud2(10, 12, kXyz, 120), pointcloud2(10, 12, kXyz, 60)},
                  "none",
                  0,
                  "topic /pts, message 1: data: holds 60 bytes"},
        BrokenBag{"unknown_datatype",
                  {pointcloud2(2, 12, {{"x", 0, 9}, {"y", 4, 7}, {"z", 8, 7}}, 24)},
                  "none",
                  0,
                  "topic /pts, message 0: fields.x: datatype 9"},
        BrokenBag{"unknown_compression", {pointcloud2(2, 12, kXyz, 24)}, "zip", 0, "unknown compression 'zip'"},
        BrokenBag{"lying_chunk_size", {pointcloud2(2, 12, kXyz, 24)}, "none", 1000000, "where its header says 1000000"},
        BrokenBag{"field_past_point_step", {pointcloud2(2, 8, kXyz, 16)}, "none", 0, "fields.z: ends at byte 12, beyond point_step 8"}),
    [](const auto& info) { return info.param.name; });

TEST(CliBag, ATopicThatIsNoPointCloudIsExitThree) {
  const fs::path dir = scratch_dir();
  const CliResult r =
      run_cli("odometry --bag " + quoted((kBags / "ros1_none.bag").string()) + " --topics /imu:a --out " + quoted((dir / "out").string()));
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("topic /imu: is sensor_msgs/Imu, not sensor_msgs/PointCloud2"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace mlidar::test
