// `mlidar simulate detection` and `mlidar perturb` from the command line: the
// perturbation stays within its sigma bounds and its stated covariance, the
// truth is kept, the copy reads as a dataset, the fused clouds carry tr(Xi),
// and bad input writes nothing.
#include <sys/stat.h>

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "mlidar/core/so3.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/run_folder.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

/// A two-frame detection dataset shared by the tests of this file (written once per test: scratch folders).
fs::path detection_dataset(const fs::path& dir) {
  const fs::path out = dir / "det";
  const CliResult result = run_cli("simulate detection --rig lyft --frames 2 --seed 3 --split test --out " + quoted(out.string()));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  return out;
}

ino_t inode(const fs::path& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 ? info.st_ino : 0;
}

TEST(CliPerturb, PerturbsAllButTheBaseWithinSigmaAndKeepsTheTruth) {
  const fs::path dir = scratch_dir();
  const fs::path det = detection_dataset(dir);
  EXPECT_EQ(io::run_folder_command(det), "simulate detection");
  const fs::path out = dir / "perturbed";
  const CliResult result = run_cli("perturb --dataset " + quoted(det.string()) + " --alpha 0.1 --seed 2 --out " + quoted(out.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("top: defines the base frame, not perturbed"), std::string::npos) << result.output;

  const io::Dataset copy = io::read_dataset_yaml(out);
  const io::Extrinsics truth = io::read_extrinsics(out / "groundtruth/extrinsics.yaml");
  EXPECT_EQ(read_text(out / "groundtruth/extrinsics.yaml"), read_text(det / "groundtruth/extrinsics.yaml"));
  const double sigma_t = std::sqrt(0.1) * 0.05, sigma_r = std::sqrt(0.1) * 0.1;
  for (const auto& lidar : copy.lidars) {
    SCOPED_TRACE(lidar.name);
    const SE3& T_true = truth.find(lidar.name)->T_base_lidar;
    ASSERT_TRUE(lidar.initial_extrinsic.has_value());
    const Vec3 rho = lidar.initial_extrinsic->translation() - T_true.translation();
    const Vec3 phi = so3_log(lidar.initial_extrinsic->rotation() * T_true.rotation().conjugate());
    if (lidar.name == "top") {
      EXPECT_EQ(rho.norm(), 0.0);
      continue;
    }
    EXPECT_GT(rho.norm(), 0.0);
    EXPECT_LE(rho.cwiseAbs().maxCoeff(), sigma_t + 1e-12);  // bounded at sigma (6.6.1.3)
    EXPECT_LE(phi.cwiseAbs().maxCoeff(), sigma_r + 1e-9);
  }
  // The perturbed extrinsics come with the prior's covariance: the error is within it (NEES of 6 dof, bounded draws).
  const io::Extrinsics stated = io::read_extrinsics(out / "extrinsics_perturbed.yaml");
  const io::LidarExtrinsic* left = stated.find("front_left");
  ASSERT_NE(left, nullptr);
  ASSERT_TRUE(left->covariance.has_value());
  EXPECT_NEAR((*left->covariance)(0, 0), sigma_t * sigma_t, 1e-15);
  EXPECT_NEAR((*left->covariance)(4, 4), sigma_r * sigma_r, 1e-15);
  const nlohmann::json record = nlohmann::json::parse(read_text(out / "groundtruth/perturbation.json"));
  EXPECT_EQ(record["alpha"], 0.1);
  EXPECT_EQ(record["lidars"]["top"]["perturbed"], false);
  // Labels and scans are carried over unchanged; a copy unless --link.
  EXPECT_EQ(read_text(out / "groundtruth/label_2/000001.txt"), read_text(det / "groundtruth/label_2/000001.txt"));
  EXPECT_EQ(read_text(out / "scans/front_right/000001.pcd"), read_text(det / "scans/front_right/000001.pcd"));
  EXPECT_NE(inode(out / "scans/front_right/000001.pcd"), inode(det / "scans/front_right/000001.pcd"));
  EXPECT_EQ(io::run_folder_command(out), "perturb");
}

TEST(CliPerturb, SameSeedSameCopyAndLinkSharesTheScans) {
  const fs::path dir = scratch_dir();
  const fs::path det = detection_dataset(dir);
  const std::string base = "perturb --dataset " + quoted(det.string()) + " --alpha 0.04 --out ";
  ASSERT_EQ(run_cli(base + quoted((dir / "a").string()) + " --seed 5").exit_code, 0);
  ASSERT_EQ(run_cli(base + quoted((dir / "b").string()) + " --seed 5 --link").exit_code, 0);
  ASSERT_EQ(run_cli(base + quoted((dir / "c").string()) + " --seed 6").exit_code, 0);
  EXPECT_EQ(read_text(dir / "a/dataset.yaml"), read_text(dir / "b/dataset.yaml"));
  EXPECT_NE(read_text(dir / "a/dataset.yaml"), read_text(dir / "c/dataset.yaml"));
  EXPECT_EQ(inode(dir / "b/scans/top/000000.pcd"), inode(det / "scans/top/000000.pcd"));
  // An earlier perturb output is replaced by perturb, like simulate's datasets.
  ASSERT_EQ(run_cli(base + quoted((dir / "a").string()) + " --seed 6").exit_code, 0);
  EXPECT_EQ(read_text(dir / "a/dataset.yaml"), read_text(dir / "c/dataset.yaml"));
}

TEST(CliPerturb, FusedCloudsCarryTheTraceOfEachPointsCovariance) {
  const fs::path dir = scratch_dir();
  const fs::path det = detection_dataset(dir);
  const fs::path out = dir / "fused";
  const CliResult result =
      run_cli("perturb --dataset " + quoted(det.string()) + " --alpha 0.02 --seed 1 --fused --out " + quoted(out.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const io::PcdCloud fused = io::read_pcd(out / "fused/000001.pcd");
  std::size_t scanned = 0;
  for (const char* lidar : {"top", "front_left", "front_right"})
    scanned += io::read_pcd(det / "scans" / lidar / "000001.pcd").table.num_points;
  ASSERT_EQ(fused.table.num_points, scanned);
  const io::FieldColumn* uncertainty = fused.table.find("uncertainty");
  const io::FieldColumn* lidar = fused.table.find("lidar");
  ASSERT_NE(uncertainty, nullptr);
  ASSERT_NE(lidar, nullptr);
  // The base-defining LiDAR's points carry eq 6.8's measurement noise alone, 3 (1/50 m)^2; the others more,
  // growing with the distance from the LiDAR (the rotation's lever).
  double near_max = 0.0, far_min = 1e9;
  for (std::size_t i = 0; i < fused.table.num_points; ++i) {
    const double trace = uncertainty->value(i);
    if (lidar->value(i) == 0) {
      EXPECT_NEAR(trace, 3.0 / 2500.0, 1e-9);
      continue;
    }
    EXPECT_GT(trace, 3.0 / 2500.0);
    const Vec3 p(fused.table.find("x")->value(i), fused.table.find("y")->value(i), fused.table.find("z")->value(i));
    const Vec3 mount = lidar->value(i) == 1 ? Vec3(3.473, 0.942, 0.543) : Vec3(3.498, -0.950, 0.547);
    const double range = (p - mount).norm();
    if (range < 5.0) near_max = std::max(near_max, trace);
    if (range > 20.0) far_min = std::min(far_min, trace);
  }
  EXPECT_LT(near_max, far_min);
}

TEST(CliPerturb, BadInputWritesNothing) {
  const fs::path dir = scratch_dir();
  const fs::path out = dir / "out";
  CliResult result = run_cli("perturb --dataset " + quoted((dir / "missing").string()) + " --alpha 0.1 --out " + quoted(out.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_FALSE(fs::exists(out));
  const fs::path det = detection_dataset(dir);
  result = run_cli("perturb --dataset " + quoted(det.string()) + " --alpha 2 --out " + quoted(out.string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  result = run_cli("perturb --dataset " + quoted(det.string()) + " --alpha 0.1 --out " + quoted(det.string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;  // never into its own input
  // A LiDAR without any extrinsic to start from: exit 3 naming it.
  fs::remove(det / "groundtruth/extrinsics.yaml");
  std::string yaml = read_text(det / "dataset.yaml");
  const auto erase_lines = [&](std::size_t from, int lines) {
    ASSERT_NE(from, std::string::npos);
    std::size_t to = from;
    for (int i = 0; i < lines; ++i) to = yaml.find('\n', to) + 1;
    yaml.erase(from, to - from);
  };
  erase_lines(yaml.find("    initial_extrinsic:", yaml.find("name: front_right")), 3);
  erase_lines(yaml.find("  extrinsics: groundtruth/extrinsics.yaml"), 1);
  { std::ofstream(det / "dataset.yaml") << yaml; }
  result = run_cli("perturb --dataset " + quoted(det.string()) + " --alpha 0.1 --out " + quoted(out.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output << yaml;
  EXPECT_NE(result.output.find("front_right"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace mlidar::test
