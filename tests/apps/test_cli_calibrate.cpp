// End-to-end `mlidar calibrate planes`: a simulated corner calibrates (exit 0,
// extrinsics YAML with covariance, JSON report); a cloud without a corner is
// bad input (exit 3); an unknown planes.yaml key is a usage error naming it (2);
// --strict turns a warning into exit 1.
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

TEST(CliCalibrate, PlanesOnASimulatedCornerAndItsFailureModes) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "corner";
  ASSERT_EQ(run_cli("simulate corner --angles 90:90 --seed 3 --out " + quoted(sim.string())).exit_code, 0);
  const std::string ref = quoted((sim / "scans" / "l1" / "000000.pcd").string());
  const std::string target = quoted((sim / "scans" / "l2" / "000000.pcd").string());
  const fs::path out = dir / "out.yaml";
  const fs::path report = dir / "report.json";
  CliResult result = run_cli("calibrate planes --ref " + ref + " --target " + target + " --out " + quoted(out.string()) + " --report " +
                             quoted(report.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const io::Extrinsics truth = io::read_extrinsics(sim / "groundtruth" / "extrinsics.yaml");
  const io::Extrinsics estimate = io::read_extrinsics(out);
  // Both clouds are named 000000.pcd: the target falls back to "target".
  ASSERT_NE(estimate.find("target"), nullptr);
  ASSERT_TRUE(estimate.find("target")->covariance.has_value());
  const SE3 error = truth.find("l2")->T_base_lidar.inverse() * estimate.find("target")->T_base_lidar;
  EXPECT_LT(error.log().norm(), 0.02);
  const auto json = nlohmann::json::parse(std::ifstream(report));
  EXPECT_EQ(json["verdict"], "ok");
  EXPECT_EQ(json["ref"]["planes"].size(), 3U);
  // --html: the clouds as recorded (no --init: identity) and after, and the warnings in words (the strict run below).
  result = run_cli("calibrate planes --ref " + ref + " --target " + target + " --out " + quoted((dir / "html.yaml").string()) + " --html " +
                   quoted((dir / "planes.html").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::string page = read_text(dir / "planes.html");
  EXPECT_NE(page.find("identity (no --init"), std::string::npos);
  EXPECT_NE(page.find("<title>After, side view</title>"), std::string::npos);
  EXPECT_NE(page.find("<li class=\"ok\">ok: three planes found"), std::string::npos);

  std::ofstream(dir / "flat.xyz.pcd") << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 400\nHEIGHT 1\n"
                                         "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 400\nDATA ascii\n";
  {
    std::ofstream flat(dir / "flat.xyz.pcd", std::ios::app);
    for (int i = 0; i < 400; ++i) flat << (i % 20) * 0.1 << ' ' << (i / 20) * 0.1 << " 0\n";
  }
  result =
      run_cli("calibrate planes --ref " + ref + " --target " + quoted((dir / "flat.xyz.pcd").string()) + " --out " + quoted(out.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;

  std::ofstream(dir / "planes.yaml") << "inlier_distance: 0.2\nransac_iters: 10\n";
  result = run_cli("calibrate planes --ref " + ref + " --target " + target + " --config " + quoted((dir / "planes.yaml").string()) +
                   " --out " + quoted(out.string()));
  EXPECT_EQ(result.exit_code, 3);  // a config file is input: FILE: KEY: problem, exit 3
  EXPECT_NE(result.output.find("planes.yaml: ransac_iters: unknown key"), std::string::npos) << result.output;

  std::ofstream(dir / "strict.yaml") << "warn_min_inliers: 100000\n";
  result = run_cli("calibrate planes --strict --ref " + ref + " --target " + target + " --config " +
                   quoted((dir / "strict.yaml").string()) + " --out " + quoted(out.string()));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("few_inliers"), std::string::npos) << result.output;
  result = run_cli("calibrate planes --ref " + ref + " --target " + target + " --config " + quoted((dir / "strict.yaml").string()) +
                   " --out " + quoted(out.string()) + " --html " + quoted((dir / "strict.html").string()));
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(read_text(dir / "strict.html").find("<li class=\"warn\">few_inliers</li>"), std::string::npos);
  EXPECT_EQ(run_cli("calibrate planes --ref " + ref).exit_code, 2);
}

}  // namespace
}  // namespace mlidar::test
