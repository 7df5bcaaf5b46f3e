// End-to-end `mlidar eval`: exit codes 0 / 2 / 3, JSON keys and values, outputs written.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

nlohmann::json read_json(const fs::path& path) { return nlohmann::json::parse(std::ifstream(path)); }

/// TUM lines of a curve; `offset_x` shifts every position along x.
std::string tum_text(int count, double offset_x = 0.0) {
  std::string text = "# t x y z qx qy qz qw\n";
  char line[256];
  for (int i = 0; i < count; ++i) {
    const double s = 0.1 * i;
    const double yaw = 0.3 * s;
    std::snprintf(line, sizeof(line), "%.6f %.17g %.17g %.17g 0 0 %.17g %.17g\n", 10.0 + 0.1 * i, 5.0 * std::cos(s) + offset_x,
                  3.0 * std::sin(s), 0.1 * s, std::sin(yaw / 2), std::cos(yaw / 2));
    text += line;
  }
  return text;
}

TEST(CliEval, TrajectoryOffsetGivesKnownAteAndAlignsAway) {
  const fs::path dir = scratch_dir();
  write_text(dir / "gt.tum", tum_text(50));
  write_text(dir / "est.tum", tum_text(50, 0.25));
  const std::string files = " --gt " + quoted((dir / "gt.tum").string()) + " --est " + quoted((dir / "est.tum").string());
  CliResult result = run_cli("eval traj" + files + " --align none --json " + quoted((dir / "none.json").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("ATE"), std::string::npos);
  EXPECT_NEAR(read_json(dir / "none.json")["ate"]["translation_m"]["rmse"].get<double>(), 0.25, 1e-9);

  result =
      run_cli("eval traj" + files + " --json " + quoted((dir / "se3.json").string()) + " --plot " + quoted((dir / "plot.svg").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = read_json(dir / "se3.json");
  EXPECT_LT(json["ate"]["translation_m"]["rmse"].get<double>(), 1e-9);
  EXPECT_EQ(json["matched_poses"].get<int>(), 50);
  std::ifstream svg(dir / "plot.svg");
  std::string first_line;
  std::getline(svg, first_line);
  EXPECT_EQ(first_line.rfind("<svg", 0), 0U);
}

TEST(CliEval, PoseCovariancesGetTheirNees) {
  // A constant offset is gone after the start alignment: zero error, every frame below the band.
  const fs::path dir = scratch_dir();
  write_text(dir / "gt.tum", tum_text(20));
  write_text(dir / "est.tum", tum_text(20, 0.25));
  std::string covariances = "# stamp, upper triangle\n";
  char line[64];
  for (int i = 0; i < 20; ++i) {
    std::snprintf(line, sizeof(line), "%.6f", 10.0 + 0.1 * i);
    covariances += line;
    for (int row = 0; row < 6; ++row)
      for (int col = row; col < 6; ++col) covariances += row == col && i > 0 ? " 0.01" : " 0";
    covariances += "\n";
  }
  write_text(dir / "pose_covariance.txt", covariances);
  const std::string files = " --gt " + quoted((dir / "gt.tum").string()) + " --est " + quoted((dir / "est.tum").string());
  CliResult result = run_cli("eval traj" + files + " --covariance " + quoted((dir / "pose_covariance.txt").string()) + " --json " +
                             quoted((dir / "nees.json").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("pose NEES (6 dof, aligned at the first pose): 0.0 % of 19 frames inside"), std::string::npos)
      << result.output;
  const auto json = read_json(dir / "nees.json");
  EXPECT_EQ(json["pose_nees"]["pose"]["frames"].get<int>(), 19);
  EXPECT_EQ(json["pose_nees"]["skipped"].get<int>(), 1);
  EXPECT_DOUBLE_EQ(json["pose_nees"]["pose"]["below"].get<double>(), 1.0);
  EXPECT_EQ(json["pose_nees"]["values"].size(), 19u);

  write_text(dir / "short.txt", "10 1 2 3\n");
  result = run_cli("eval traj" + files + " --covariance " + quoted((dir / "short.txt").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find((dir / "short.txt").string()), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("expected 22 values"), std::string::npos) << result.output;
}

TEST(CliEval, BadTrajectoriesExitThree) {
  const fs::path dir = scratch_dir();
  write_text(dir / "gt.tum", tum_text(20));
  std::string nan_pose = tum_text(20);
  nan_pose.replace(nan_pose.find('\n', nan_pose.find('\n') + 1) + 1, 0, "10.05 nan 0 0 0 0 0 1\n");
  std::string backwards = tum_text(5) + "9.0 0 0 0 0 0 0 1\n";
  const struct {
    const char* name;
    std::string text;
  } cases[] = {
      {"nan.tum", nan_pose},
      {"backwards.tum", backwards},
      {"empty.tum", "# nothing\n"},
      {"one.tum", "10.0 0 0 0 0 0 0 1\n"},
      {"kitti_rows.tum", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n"},
      {"other_clock.tum", "500.0 0 0 0 0 0 0 1\n500.1 1 0 0 0 0 0 1\n500.2 2 0 0 0 0 0 1\n"},
  };
  for (const auto& bad : cases) {
    write_text(dir / bad.name, bad.text);
    const CliResult result = run_cli("eval traj --gt " + quoted((dir / "gt.tum").string()) + " --est " + quoted((dir / bad.name).string()));
    EXPECT_EQ(result.exit_code, 3) << bad.name << ": " << result.output;
    EXPECT_NE(result.output.find(bad.name), std::string::npos) << bad.name << ": " << result.output;
  }
}

TEST(CliEval, UsageErrorsExitTwo) {
  const fs::path dir = scratch_dir();
  write_text(dir / "gt.tum", tum_text(20));
  const std::string files = " --gt " + quoted((dir / "gt.tum").string()) + " --est " + quoted((dir / "gt.tum").string());
  EXPECT_EQ(run_cli("eval traj" + files + " --align affine").exit_code, 2);
  EXPECT_EQ(run_cli("eval traj" + files + " --delta 0").exit_code, 2);
  EXPECT_EQ(run_cli("eval traj --gt x").exit_code, 2);
  EXPECT_EQ(run_cli("eval").exit_code, 2);
  EXPECT_EQ(run_cli("eval map --map x.ply --radius 0").exit_code, 2);
}

TEST(CliEval, CalibrationRotationError) {
  const fs::path dir = scratch_dir();
  write_text(dir / "gt.yaml", "base: base\nlidars:\n  top:\n    translation: [0, 0, 1]\n    quaternion_wxyz: [1, 0, 0, 0]\n");
  // 2 degrees about z: w = cos(1 deg), z = sin(1 deg).
  char est[512];
  std::snprintf(est, sizeof(est),
                "base: base\nlidars:\n  top:\n    translation: [0.03, 0.04, 1]\n    quaternion_wxyz: [%.17g, 0, 0, %.17g]\n",
                std::cos(std::numbers::pi / 180.0), std::sin(std::numbers::pi / 180.0));
  write_text(dir / "est.yaml", est);
  const CliResult result = run_cli("eval calib --gt " + quoted((dir / "gt.yaml").string()) + " --est " +
                                   quoted((dir / "est.yaml").string()) + " --json " + quoted((dir / "c.json").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = read_json(dir / "c.json");
  EXPECT_NEAR(json["lidars"][0]["rotation_error_deg"].get<double>(), 2.0, 1e-9);
  EXPECT_NEAR(json["lidars"][0]["translation_error_m"].get<double>(), 0.05, 1e-12);
}

TEST(CliEval, MapEntropyOfGaussianCloud) {
  const fs::path dir = scratch_dir();
  Scan scan;
  std::mt19937 rng(2);
  std::normal_distribution<float> normal(0.0F, 0.2F);
  for (int i = 0; i < 2000; ++i) scan.points.emplace_back(normal(rng), normal(rng), normal(rng));
  io::CloudFile cloud;
  cloud.format = io::CloudFormat::kPly;
  cloud.table = io::from_scan(scan);
  io::write_cloud(dir / "map.ply", cloud);
  const CliResult result =
      run_cli("eval map --map " + quoted((dir / "map.ply").string()) + " --radius 50 --json " + quoted((dir / "m.json").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = read_json(dir / "m.json");
  EXPECT_EQ(json["points_used"].get<int>(), 2000);
  const double closed_form = 1.5 * std::log(2.0 * std::numbers::pi * std::numbers::e * 0.04);
  EXPECT_NEAR(json["mean_map_entropy"].get<double>(), closed_form, 0.1);
  EXPECT_EQ(run_cli("eval map --map " + quoted((dir / "missing.ply").string())).exit_code, 3);
}

}  // namespace
}  // namespace mlidar::test
