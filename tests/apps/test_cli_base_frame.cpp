// A base frame that is no LiDAR (lyft's vehicle frame, placed by its roof
// LiDAR: dataset.yaml reference_lidar): slam and calibrate auto estimate
// relative to the roof LiDAR and write their results in the vehicle frame.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "apps/dataset_variants.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "pose_error.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

TEST(CliBaseFrame, SlamWritesTheVehicleFrame) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "sim";
  ASSERT_EQ(run_cli("simulate drive --rig lyft --scene street --trajectory vehicle --frames 10 --seed 3 --out " + quoted(sim.string())).exit_code,
            0);
  const io::Dataset dataset = io::read_dataset_yaml(sim);
  EXPECT_EQ(dataset.base, "vehicle");
  EXPECT_EQ(dataset.reference_lidar, "top");
  const CliResult r = run_cli("slam --calibrate fixed --threads 1 --dataset " + quoted(sim.string()) + " --out " + quoted((dir / "run").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Fixed mode with the true extrinsics: the output is the truth, in the vehicle frame (the roof LiDAR too).
  const io::Extrinsics truth = io::read_extrinsics(sim / "groundtruth" / "extrinsics.yaml");
  const io::Extrinsics written = io::read_extrinsics(dir / "run" / "extrinsics.yaml");
  EXPECT_EQ(written.base, "vehicle");
  for (const char* name : {"top", "front_left", "front_right"}) {
    ASSERT_NE(written.find(name), nullptr) << name;
    EXPECT_LT(translation_error_m(written.find(name)->T_base_lidar, truth.find(name)->T_base_lidar), 1e-9) << name;
    EXPECT_LT(rotation_error_deg(written.find(name)->T_base_lidar, truth.find(name)->T_base_lidar), 1e-7) << name;
  }
  // The trajectory is the vehicle's: its displacement over the run matches the truth's (the roof LiDAR's would
  // differ by the lever arm of 1.2 m during the turns).
  const Trajectory gt = io::read_tum(sim / "groundtruth" / "trajectory.tum");
  const Trajectory est = io::read_tum(dir / "run" / "trajectory.tum");
  ASSERT_EQ(est.size(), gt.size());
  const SE3 truth_motion = gt.poses.front().T_world_base.inverse() * gt.poses.back().T_world_base;
  const SE3 estimated_motion = est.poses.front().T_world_base.inverse() * est.poses.back().T_world_base;
  EXPECT_LT(translation_error_m(truth_motion, estimated_motion), 0.05);
}

// odometry judges given extrinsics against the map where the base frame is no LiDAR too: against the reference
// LiDAR (the roof's), as slam does. The truth passes; a front LiDAR given Table 4.6's shock (10 deg about each axis,
// 0.1 m along each) is reported by name, compared with the roof LiDAR, exit 1.
TEST(CliBaseFrame, OdometryJudgesGivenExtrinsicsAgainstTheReferenceLidar) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "sim";
  ASSERT_EQ(
      run_cli("simulate drive --rig lyft --scene street --trajectory vehicle --frames 12 --seed 3 --out " + quoted(sim.string())).exit_code,
      0);
  std::ofstream(dir / "check.yaml") << "extrinsic_check:\n  frames: 5\n";  // a verdict within the short drive
  const std::string common =
      "odometry --threads 1 --dataset " + quoted(sim.string()) + " --config " + quoted((dir / "check.yaml").string());

  const CliResult right = run_cli(common + " --extrinsics " + quoted((sim / "groundtruth" / "extrinsics.yaml").string()) + " --out " +
                                  quoted((dir / "truth").string()));
  ASSERT_EQ(right.exit_code, 0) << right.output;
  EXPECT_TRUE(nlohmann::json::parse(std::ifstream(dir / "truth" / "metrics.json"))["extrinsic_check"].empty());

  io::write_extrinsics(dir / "wrong.yaml", perturbed_truth(sim, "front_left", 10.0, 0.1));
  const CliResult wrong =
      run_cli(common + " --extrinsics " + quoted((dir / "wrong.yaml").string()) + " --out " + quoted((dir / "wrong").string()));
  EXPECT_EQ(wrong.exit_code, 1) << wrong.output;
  EXPECT_NE(wrong.output.find("warning: front_left: the given extrinsic disagrees with the map ("), std::string::npos) << wrong.output;
  const nlohmann::json check = nlohmann::json::parse(std::ifstream(dir / "wrong" / "metrics.json"))["extrinsic_check"];
  ASSERT_EQ(check.size(), 1u) << check;
  EXPECT_EQ(check[0]["lidar"], "front_left");
  ASSERT_TRUE(check[0]["residual_ratio"].is_number()) << check;
  EXPECT_GT(check[0]["residual_ratio"].get<double>(), 2.0);
  EXPECT_EQ(check[0]["compared_with"], "the reference LiDAR top");
  EXPECT_NE(wrong.output.find("x the reference LiDAR top's"), std::string::npos) << wrong.output;
}

TEST(CliBaseFrame, AMissingReferenceIsExitThreeNamingTheKey) {
  const fs::path dir = scratch_dir();
  std::ofstream(dir / "dataset.yaml") << "name: x\nframe_period: 0.1\nbase: vehicle\nlidars:\n  - {name: top, model: m, scans: scans/top}\n";
  std::ofstream(dir / "times.txt") << "0\n";
  const CliResult r = run_cli("odometry --dataset " + quoted(dir.string()) + " --out " + quoted((dir / "run").string()));
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("dataset.yaml: base: names no LiDAR of lidars (top)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("reference_lidar"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mlidar::test
