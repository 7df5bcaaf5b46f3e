// A base frame that is no LiDAR (lyft's vehicle frame, placed by its roof
// LiDAR: dataset.yaml reference_lidar): slam and calibrate auto estimate
// relative to the roof LiDAR and write their results in the vehicle frame.
#include <fstream>

#include <gtest/gtest.h>

#include "apps/cli_runner.hpp"
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
