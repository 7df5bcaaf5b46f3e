// End-to-end `mlidar calibrate auto` on small simulated drives: a handheld
// (non-planar) rhd drive calibrates from no initial guess (exit 0, both files,
// covariance); listing the LiDARs in another order gives the same extrinsics;
// a static rig is reported as unusable motion (exit 1); a bad stage is a usage error.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "apps/dataset_variants.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

TEST(CliAutoCalib, HandheldRhdFromNoGuessAndOrderIndependent) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "rhd";
  ASSERT_EQ(
      run_cli("simulate drive --rig rhd --scene campus --trajectory handheld --frames 50 --seed 1 --out " + quoted(sim.string())).exit_code,
      0);
  const fs::path run = dir / "run";
  const CliResult result = run_cli("calibrate auto --dataset " + quoted(sim.string()) + " --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const io::Extrinsics truth = io::read_extrinsics(sim / "groundtruth" / "extrinsics.yaml");
  const io::Extrinsics estimate = io::read_extrinsics(run / "extrinsics.yaml");
  EXPECT_EQ(estimate.base, "left");
  ASSERT_NE(estimate.find("right"), nullptr);
  ASSERT_TRUE(estimate.find("right")->covariance.has_value());
  ASSERT_NE(truth.find("right"), nullptr);
  const SE3& T_true = truth.find("right")->T_base_lidar;
  const SE3& T_est = estimate.find("right")->T_base_lidar;
  // Hand-eye alone on 50 frames of odometry (the initial guess in dataset.yaml is not used).
  EXPECT_LT(rotation_error_deg(T_true, T_est), 1.0);
  EXPECT_LT(translation_error_m(T_true, T_est), 0.3);
  const auto json = nlohmann::json::parse(std::ifstream(run / "calibration.json"));
  EXPECT_EQ(json["lidars"][1]["handeye"]["verdict"], "ok");
  EXPECT_GT(json["lidars"][1]["handeye"]["pairs_used"].get<int>(), 10);
  EXPECT_EQ(json["lidars"][1]["handeye"]["singular_values"].size(), 4u);
  // report.html: the right LiDAR's verdict, and its stages against the dataset's ground truth.
  const std::string report = read_text(run / "report.html");
  EXPECT_NE(report.find("<li class=\"ok\">right: calibrated (ok)</li>"), std::string::npos);
  EXPECT_NE(report.find("<section id=\"stages\">"), std::string::npos);
  EXPECT_NE(report.find("<td>right</td><td>hand-eye</td>"), std::string::npos);
  EXPECT_NE(report.find("error vs ground truth"), std::string::npos);

  const fs::path reversed = dataset_variant(sim, dir / "reversed", true, false);
  const fs::path run2 = dir / "run2";
  ASSERT_EQ(run_cli("calibrate auto --dataset " + quoted(reversed.string()) + " --base left --out " + quoted(run2.string())).exit_code, 0);
  const io::Extrinsics reordered = io::read_extrinsics(run2 / "extrinsics.yaml");
  ASSERT_NE(reordered.find("right"), nullptr);
  const SE3 T_reordered = reordered.find("right")->T_base_lidar;
  EXPECT_LT(rotation_error_deg(T_est, T_reordered), 0.01);
  EXPECT_LT(translation_error_m(T_est, T_reordered), 0.001);
}

TEST(CliAutoCalib, StaticRigIsReportedNotCalibrated) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "static";
  ASSERT_EQ(
      run_cli("simulate drive --rig rhd --scene campus --trajectory static --frames 12 --seed 1 --out " + quoted(sim.string())).exit_code,
      0);
  const fs::path run = dir / "run";
  const CliResult result = run_cli("calibrate auto --dataset " + quoted(sim.string()) + " --out " + quoted(run.string()));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  const auto json = nlohmann::json::parse(std::ifstream(run / "calibration.json"));
  EXPECT_NE(json["lidars"][1]["handeye"]["verdict"], "ok");
  EXPECT_FALSE(json["all_usable"].get<bool>());
  const std::string report = read_text(run / "report.html");
  EXPECT_NE(report.find("<li class=\"bad\">right: " + json["lidars"][1]["verdict"].get<std::string>()), std::string::npos) << report;
  EXPECT_EQ(run_cli("calibrate auto --dataset " + quoted(sim.string()) + " --stage polish --out " + quoted((dir / "x").string())).exit_code,
            2);
  EXPECT_EQ(run_cli("calibrate auto --dataset " + quoted(sim.string()) + " --base nosuch --out " + quoted((dir / "y").string())).exit_code,
            2);
}

}  // namespace
}  // namespace mlidar::test
