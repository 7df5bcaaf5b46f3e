// End-to-end `mlidar calibrate refine` on a real OpenCalib pair: exit 0 and an
// extrinsics YAML that io reads back (reference identity, target with
// covariance) agreeing with the JSON report; a bad --init is bad input (exit
// 3) naming the file and the field; a missing option is a usage error (2).
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

fs::path scene() { return shared_data() / "real" / "opencalib_3lidar" / "0001"; }

std::string pair_arguments() {
  // lidar_cloud_path.txt of scene 0001: device 0 = top.pcd, 2 = right.pcd.
  return "calibrate refine --ref " + quoted((scene() / "top.pcd").string()) + " --target " + quoted((scene() / "right.pcd").string()) +
         " --ref-name top --target-name right --target-id 2";
}

TEST(CliCalibrateRefine, RealPairWritesExtrinsicsThatReadBack) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const fs::path out = dir / "out.yaml";
  const fs::path report = dir / "report.json";
  const CliResult result = run_cli(pair_arguments() + " --init " + quoted((scene() / "initial_extrinsic.txt").string()) + " --out " +
                                   quoted(out.string()) + " --report " + quoted(report.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("verdict"), std::string::npos) << result.output;
  const io::Extrinsics extrinsics = io::read_extrinsics(out);
  EXPECT_EQ(extrinsics.base, "top");
  ASSERT_NE(extrinsics.find("top"), nullptr);
  EXPECT_TRUE(extrinsics.find("top")->T_base_lidar.log().isZero());
  const io::LidarExtrinsic* right = extrinsics.find("right");
  ASSERT_NE(right, nullptr);
  ASSERT_TRUE(right->covariance.has_value());
  const auto json = nlohmann::json::parse(std::ifstream(report));
  EXPECT_NE(json["verdict"], "not_converged");
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(json["T_ref_target"]["translation"][i].get<double>(), right->T_base_lidar.translation()(i), 1e-9);
  EXPECT_EQ(json["covariance"].size(), 36U);

  // --html: the page with both clouds overlaid before and after (its geometry: tests/report/test_pair_report.cpp).
  const fs::path html = dir / "pair.html";
  ASSERT_EQ(run_cli(pair_arguments() + " --init " + quoted((scene() / "initial_extrinsic.txt").string()) + " --out " +
                    quoted((dir / "again.yaml").string()) + " --html " + quoted(html.string()))
                .exit_code,
            0);
  const std::string page = read_text(html);
  for (const char* title : {"Before, top view", "After, top view", "Before, side view", "After, side view"})
    EXPECT_NE(page.find("<title>" + std::string(title) + "</title>"), std::string::npos) << title;
  EXPECT_NE(page.find("<li class=\"ok\">"), std::string::npos);
  EXPECT_EQ(page.find("http"), std::string::npos);
  // An existing folder as --html is a usage error before any work.
  EXPECT_EQ(run_cli(pair_arguments() + " --init " + quoted((scene() / "initial_extrinsic.txt").string()) + " --out " +
                    quoted((dir / "third.yaml").string()) + " --html " + quoted(dir.string()))
                .exit_code,
            2);
  EXPECT_FALSE(fs::exists(dir / "third.yaml"));
}

TEST(CliCalibrateRefine, BadInitIsBadInputNamingFileAndField) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const fs::path bad = dir / "bad_init.txt";
  std::ofstream(bad) << "device_id: 0\n(Roll,Pitch,Yaw,tx,ty,tz): 0 0 0 0 0 0\n"
                        "device_id: 2\n(Roll,Pitch,Yaw,tx,ty,tz): 0 0 abc 0 0 0\n";
  CliResult result = run_cli(pair_arguments() + " --init " + quoted(bad.string()) + " --out " + quoted((dir / "o.yaml").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("bad_init.txt"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("line 4"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir / "o.yaml"));

  const fs::path yaml = dir / "init.yaml";
  std::ofstream(yaml) << "base: top\nlidars:\n  top:\n    translation: [0, 0, 0]\n    quaternion_wxyz: [1, 0, 0, 0]\n";
  result = run_cli(pair_arguments() + " --init " + quoted(yaml.string()) + " --out " + quoted((dir / "o.yaml").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("lidars.right"), std::string::npos) << result.output;
}

// A newcomer's guess file names its LiDARs as they are called on the robot: the
// reference is its base and the target its one other LiDAR, without --ref-name
// / --target-name; the output uses the same names. With several other LiDARs
// the message lists them and asks for --target-name.
TEST(CliCalibrateRefine, NamesComeFromTheGuessFileWhenNotGiven) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const std::string clouds =
      "calibrate refine --ref " + quoted((scene() / "top.pcd").string()) + " --target " + quoted((scene() / "right.pcd").string());
  // The guess of scene 0001's initial_extrinsic.txt for device 2, as an extrinsics YAML (rounded).
  const fs::path reference = dir / "reference.yaml";
  ASSERT_EQ(
      run_cli(pair_arguments() + " --init " + quoted((scene() / "initial_extrinsic.txt").string()) + " --out " + quoted(reference.string()))
          .exit_code,
      0);
  const io::Extrinsics refined = io::read_extrinsics(reference);
  const SE3 T_top_right = refined.find("right")->T_base_lidar;
  io::Extrinsics guess;
  guess.base = "roof";
  guess.lidars = {{"roof", SE3(), std::nullopt},
                  {"bumper_right", SE3(T_top_right.rotation(), T_top_right.translation() + Vec3(0.03, -0.02, 0.0)), std::nullopt}};
  const fs::path init = dir / "guess.yaml";
  io::write_extrinsics(init, guess);
  const fs::path out = dir / "out.yaml";
  CliResult result = run_cli(clouds + " --init " + quoted(init.string()) + " --out " + quoted(out.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const io::Extrinsics written = io::read_extrinsics(out);
  EXPECT_EQ(written.base, "roof");
  ASSERT_NE(written.find("bumper_right"), nullptr);
  EXPECT_LT((written.find("bumper_right")->T_base_lidar.translation() - T_top_right.translation()).norm(), 0.01);

  guess.lidars.push_back({"bumper_left", SE3(), std::nullopt});
  io::write_extrinsics(init, guess);
  result = run_cli(clouds + " --init " + quoted(init.string()) + " --out " + quoted((dir / "o2.yaml").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("bumper_right, bumper_left"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("--target-name"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir / "o2.yaml"));
  result = run_cli(clouds + " --init " + quoted(init.string()) + " --target-name bumper_right --out " + quoted((dir / "o3.yaml").string()));
  EXPECT_EQ(result.exit_code, 0) << result.output;
}

TEST(CliCalibrateRefine, MissingOptionIsUsage) {
  const CliResult result = run_cli("calibrate refine --ref a.pcd --target b.pcd --init i.txt");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--out"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace mlidar::test
