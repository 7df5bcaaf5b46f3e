// End-to-end `mlidar odometry`: on a simulated rv/campus drive (dataset and a
// single LiDAR's folder of PCDs) the run folder holds a trajectory that matches
// the simulator's ground truth, a readable map and metrics; bad input exits 3
// and leaves no run folder behind.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "apps/dataset_variants.hpp"
#include "mlidar/eval/trajectory_metrics.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/pose_covariance_io.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 8;
constexpr double kMaxAteM = 0.05;
// A folder of one LiDAR's clouds has no model, but its PCDs keep the ring
// channel: the rows come from it with angles measured from the points, and the
// full front end runs (measured 0.0018 m here, seed 5, the top LiDAR alone at
// 7.5 m/s; voxel samples as the only features measured 0.068 m).
constexpr double kMaxScanFolderAteM = 0.01;

/// Checks every file of a run folder parses and returns its TUM trajectory.
Trajectory read_run_folder(const fs::path& run) {
  const Trajectory tum = io::read_tum(run / "trajectory.tum");
  EXPECT_EQ(tum.poses.size(), static_cast<std::size_t>(kFrames));
  const Trajectory kitti = io::read_kitti_poses(run / "trajectory.kitti");
  EXPECT_EQ(kitti.poses.size(), tum.poses.size());
  for (std::size_t k = 0; k < std::min(kitti.poses.size(), tum.poses.size()); ++k)
    EXPECT_LT((kitti.poses[k].T_world_base.inverse() * tum.poses[k].T_world_base).log().norm(), 1e-6) << "frame " << k;
  const io::CloudFile map = io::read_cloud(run / "map.ply");
  EXPECT_GT(map.table.num_points, 1000U);
  const auto metrics = nlohmann::json::parse(std::ifstream(run / "metrics.json"));
  EXPECT_EQ(metrics["frames"].get<int>(), kFrames);
  // One covariance per frame, at the trajectory's stamps: zero at the first frame, then positive definite.
  const auto covariances = io::read_pose_covariances(run / "pose_covariance.txt");
  EXPECT_EQ(covariances.size(), tum.poses.size());
  for (std::size_t k = 0; k < std::min(covariances.size(), tum.poses.size()); ++k) {
    EXPECT_EQ(covariances[k].stamp, tum.poses[k].stamp);
    if (k == 0) {
      EXPECT_EQ(covariances[k].covariance.norm(), 0.0);
    } else {
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat6>(covariances[k].covariance).eigenvalues().minCoeff(), 0.0) << k;
    }
  }
  EXPECT_EQ(metrics["lost_frames"].get<int>(), 0);
  EXPECT_EQ(metrics["per_frame"].size(), static_cast<std::size_t>(kFrames));
  return tum;
}

/// Translation ATE (m) after SE(3) alignment, poses paired by stamp.
double ate_rmse(const Trajectory& gt, const Trajectory& est) {
  const auto report = eval::evaluate_trajectory(gt, est, {}, "groundtruth", "estimate");
  EXPECT_EQ(report.ate.translation_m.count, static_cast<std::size_t>(kFrames));
  return report.ate.translation_m.rmse;
}

/// Simulates the drive into dir/sim (per test: ctest runs tests as parallel processes).
fs::path simulate_drive(const fs::path& dir) {
  const fs::path sim = dir / "sim";
  const auto result = run_cli("simulate drive --rig rv --scene campus --trajectory vehicle --frames " + std::to_string(kFrames) +
                              " --seed 5 --out " + quoted(sim.string()));
  EXPECT_EQ(result.exit_code, 0) << result.output;
  return sim;
}

TEST(CliOdometry, DatasetRunTracksTheGroundTruth) {
  const fs::path dir = scratch_dir();
  const fs::path sim = simulate_drive(dir);
  const fs::path run = dir / "run";
  const auto result = run_cli("odometry --dataset " + quoted(sim.string()) + " --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const Trajectory est = read_run_folder(run);
  const Trajectory gt = io::read_tum(sim / "groundtruth" / "trajectory.tum");
  EXPECT_LT(ate_rmse(gt, est), kMaxAteM);
}

// In a corridor along the base's x the translation along it is not observable
// from geometry: the terminal and metrics.json name that direction.
TEST(CliOdometry, DegenerateFramesNameTheirUnobservableDirection) {
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "sim";
  ASSERT_EQ(run_cli("simulate drive --rig rv --scene corridor --trajectory corridor --frames " + std::to_string(kFrames) +
                    " --seed 1 --out " + quoted(sim.string()))
                .exit_code,
            0);
  const fs::path run = dir / "run";
  const auto result = run_cli("odometry --dataset " + quoted(sim.string()) + " --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("degenerate (translation weakly constrained, e.g. a corridor): along the base's x (forward-backward) in "),
            std::string::npos)
      << result.output;
  const auto metrics = nlohmann::json::parse(std::ifstream(run / "metrics.json"));
  const int degenerate = metrics["degenerate_frames"].get<int>();
  EXPECT_GE(degenerate, kFrames - 1);
  EXPECT_EQ(metrics["degenerate_directions"]["x (forward-backward)"].get<int>(), degenerate);
  for (const auto& frame : metrics["per_frame"]) {
    if (!frame["degenerate"].get<bool>()) continue;
    EXPECT_EQ(frame["weak_direction"], "x (forward-backward)");
    EXPECT_GT(std::abs(frame["weak_translation_base"][0].get<double>()), 0.95);
  }
  // The pose covariance grows along the corridor's axis (the base's x is the world's here), far beyond the
  // measured directions, and covers the true error there (the motion along the axis is never measured).
  const auto covariances = io::read_pose_covariances(run / "pose_covariance.txt");
  ASSERT_EQ(covariances.size(), static_cast<std::size_t>(kFrames));
  const Trajectory gt = io::read_tum(sim / "groundtruth" / "trajectory.tum");
  const Trajectory est = io::read_tum(run / "trajectory.tum");
  double previous = 0.0;
  for (std::size_t k = 1; k < covariances.size(); ++k) {
    const Mat6& c = covariances[k].covariance;
    EXPECT_GT(c(0, 0), previous) << k;
    previous = c(0, 0);
    EXPECT_GT(c(0, 0), 20.0 * std::max(c(1, 1), c(2, 2))) << k;
    EXPECT_NEAR(metrics["per_frame"][k]["pose_covariance_trace"].get<double>(), c.trace(), 1e-12 * c.trace());
  }
  const double error_x = (gt.poses.back().T_world_base.translation() - est.poses.back().T_world_base.translation()).x();
  EXPECT_LT(std::abs(error_x), 3.0 * std::sqrt(covariances.back().covariance(0, 0))) << error_x;
}

TEST(CliOdometry, ScanFolderOfOneLidarTracksThatLidar) {
  const fs::path dir = scratch_dir();
  const fs::path sim = simulate_drive(dir);
  const fs::path run = dir / "run";
  const auto result =
      run_cli("odometry --scans " + quoted((sim / "scans" / "top").string()) + " --period 0.1 --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("rows from its ring channel in 8 of 8 frames (16 rings"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("note: last pose 1-sigma x "), std::string::npos) << result.output;
  const Trajectory est = read_run_folder(run);
  // The folder's trajectory is the top LiDAR's: T_world_top = T_world_base T_base_top.
  Trajectory gt = io::read_tum(sim / "groundtruth" / "trajectory.tum");
  const io::Extrinsics truth = io::read_extrinsics(sim / "groundtruth" / "extrinsics.yaml");
  ASSERT_NE(truth.find("top"), nullptr);
  for (auto& stamped : gt.poses) stamped.T_world_base = stamped.T_world_base * truth.find("top")->T_base_lidar;
  EXPECT_LT(ate_rmse(gt, est), kMaxScanFolderAteM);
}

TEST(CliOdometry, ScanFolderTakesTheNamedModel) {
  // `--model NAME`: the clouds' rows from the named LiDAR's vertical angles (rv's top is an RS-LiDAR-16).
  const fs::path dir = scratch_dir();
  const fs::path sim = simulate_drive(dir);
  const fs::path scans = sim / "scans" / "top";
  const fs::path run = dir / "run";
  CliResult result =
      run_cli("odometry --scans " + quoted(scans.string()) + " --period 0.1 --model RS-LiDAR-16 --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  read_run_folder(run);
  const auto metrics = nlohmann::json::parse(std::ifstream(run / "metrics.json"));
  EXPECT_EQ(metrics["front_end"]["lidar"]["frames_by_source"]["model"].get<int>(), kFrames) << metrics["front_end"].dump();
  EXPECT_EQ(metrics["per_frame"][0]["front_end"]["lidar"]["rows"].get<int>(), 16);
  // An unknown model or one without --scans is a usage error naming the known ones; nothing is written.
  const fs::path bad = dir / "bad";
  result = run_cli("odometry --scans " + quoted(scans.string()) + " --model OS9-512 --out " + quoted(bad.string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("OS0-64"), std::string::npos) << result.output;
  result = run_cli("odometry --dataset " + quoted(sim.string()) + " --model VLP-16 --out " + quoted(bad.string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_FALSE(fs::exists(bad));
}

// `--config` takes the slam config's `selection` section (thesis Ch. 5): the
// run still tracks the drive, and metrics.json says per frame and per LiDAR
// how many features were chosen; `slam --config` reports the same. A bad key
// is exit 3 naming it, with no run folder left.
TEST(CliOdometry, ConfigSelectsGoodFeaturesAndMetricsSayHowMany) {
  const fs::path dir = scratch_dir();
  const fs::path sim = simulate_drive(dir);
  std::ofstream(dir / "greedy.yaml") << "selection:\n  method: greedy\n  ratio: 0.25\n";
  const fs::path run = dir / "run";
  auto result = run_cli("odometry --dataset " + quoted(sim.string()) + " --config " + quoted((dir / "greedy.yaml").string()) + " --out " +
                        quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const Trajectory est = read_run_folder(run);
  EXPECT_LT(ate_rmse(io::read_tum(sim / "groundtruth" / "trajectory.tum"), est), kMaxAteM);
  const auto metrics = nlohmann::json::parse(std::ifstream(run / "metrics.json"));
  EXPECT_TRUE(metrics["per_frame"][0]["selection"].is_null());  // the first frame only builds the map
  for (std::size_t k = 1; k < static_cast<std::size_t>(kFrames); ++k) {
    const auto& selection = metrics["per_frame"][k]["selection"];
    ASSERT_TRUE(selection.is_object()) << k;
    EXPECT_EQ(selection["method"], "greedy");
    const auto features = selection["features"].get<std::size_t>();
    EXPECT_EQ(features, metrics["per_frame"][k]["edges"].get<std::size_t>() + metrics["per_frame"][k]["planes"].get<std::size_t>());
    const double share = selection["degenerate_scene"].get<bool>() ? 0.8 : 0.25;  // sec 5.4.4, adaptive by default
    if (!selection["fell_back"].get<bool>()) {
      EXPECT_EQ(selection["selected"].get<std::size_t>(), static_cast<std::size_t>(std::ceil(share * static_cast<double>(features))));
    }
    ASSERT_EQ(selection["per_lidar"].size(), 4u);
    for (const char* lidar : {"top", "front", "left", "right"}) EXPECT_GT(selection["per_lidar"][lidar]["selected"].get<int>(), 0) << lidar;
    EXPECT_TRUE(selection["log_det_selected"].is_number());
  }
  const fs::path slam_run = dir / "slam";
  result = run_cli("slam --dataset " + quoted(sim.string()) + " --calibrate fixed --config " + quoted((dir / "greedy.yaml").string()) +
                   " --out " + quoted(slam_run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto slam_metrics = nlohmann::json::parse(std::ifstream(slam_run / "metrics.json"));
  EXPECT_EQ(slam_metrics["per_frame"][2]["selection"]["method"], "greedy");
  EXPECT_EQ(slam_metrics["per_frame"][2]["selection"]["per_lidar"].size(), 4u);

  std::ofstream(dir / "bad.yaml") << "selection:\n  method: best\n";
  const fs::path bad_run = dir / "bad";
  result = run_cli("odometry --dataset " + quoted(sim.string()) + " --config " + quoted((dir / "bad.yaml").string()) + " --out " +
                   quoted(bad_run.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("selection.method"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("bad.yaml"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(bad_run));
}

TEST(CliOdometry, BadInputExitsThreeAndWritesNothing) {
  const fs::path dir = scratch_dir();
  const fs::path run = dir / "run";
  auto result = run_cli("odometry --dataset " + quoted((dir / "missing").string()) + " --out " + quoted(run.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_FALSE(fs::exists(run));
  fs::create_directories(dir / "empty");
  std::ofstream(dir / "empty" / "notes.txt") << "no clouds here\n";
  result = run_cli("odometry --scans " + quoted((dir / "empty").string()) + " --out " + quoted(run.string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("no .pcd"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(run));
}

// Real BALM keyframes 20..27 with the sixth (index 5) given 12 cm of point noise:
// it fits clearly worse than the frames before, so the terminal and metrics.json
// name it suspect, and the run still exits 0 with every frame's pose.
TEST(CliOdometry, AFrameThatFitsWorseIsNamedSuspect) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const fs::path frames = dir / "frames";
  fs::create_directories(frames);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0F, 0.12F);
  for (int k = 20; k < 28; ++k) {
    const std::string name = "full" + std::to_string(k) + ".pcd";
    io::CloudFile cloud = io::read_cloud(shared_data() / "real" / "balm_ouster" / "frames" / name);
    if (k == 25) {
      for (const char* axis : {"x", "y", "z"}) {
        io::FieldColumn* column = cloud.table.find(axis);
        ASSERT_NE(column, nullptr);
        ASSERT_EQ(column->type, io::ScalarType::kF32);
        auto* values = reinterpret_cast<float*>(column->data.data());
        for (std::size_t i = 0; i < cloud.table.num_points; ++i) values[i] += noise(rng);
      }
    }
    io::write_cloud(frames / name, cloud);
  }
  const fs::path run = dir / "run";
  const CliResult result = run_cli("odometry --scans " + quoted(frames.string()) + " --period 0.5 --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("0 lost, 1 suspect"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("1 frame suspect (frame 5,"), std::string::npos) << result.output;
  const auto metrics = nlohmann::json::parse(std::ifstream(run / "metrics.json"));
  EXPECT_EQ(metrics["suspect_frames"], 1);
  ASSERT_EQ(metrics["per_frame"].size(), 8u);
  for (std::size_t k = 0; k < 8; ++k) {
    EXPECT_EQ(metrics["per_frame"][k]["suspect"], k == 5) << "frame " << k;
    EXPECT_EQ(metrics["per_frame"][k]["trust"], k == 5 ? "residual" : "trusted") << "frame " << k;
  }
  EXPECT_GT(metrics["per_frame"][5]["mean_residual_m"].get<double>(), 2.0 * metrics["per_frame"][5]["recent_residual_m"].get<double>());
  EXPECT_EQ(io::read_tum(run / "trajectory.tum").poses.size(), 8u);
}

// A given extrinsic far from the truth (Table 4.6's shock: 10 deg about each axis, 0.1 m along each) leaves the
// LiDAR's residual against the map 3-4x the base's: reported by name with its frame, exit 1; the true one is not.
TEST(CliOdometry, AGivenExtrinsicThatDisagreesWithTheMapIsReported) {
  constexpr int kCheckFrames = 12;
  const fs::path dir = scratch_dir();
  const fs::path sim = dir / "sim";
  ASSERT_EQ(run_cli("simulate drive --rig rhd --scene campus --trajectory handheld --frames " + std::to_string(kCheckFrames) +
                    " --seed 1 --out " + quoted(sim.string()))
                .exit_code,
            0);
  io::Extrinsics wrong = io::read_extrinsics(sim / "groundtruth" / "extrinsics.yaml");
  const double deg = 0.017453292519943295;
  Vec6 shock;  // the translation in the LiDAR's frame (SE3::exp): the verdict's frame below was measured with it
  shock << 0.1, 0.1, 0.1, 10 * deg, 10 * deg, 10 * deg;
  for (auto& lidar : wrong.lidars)
    if (lidar.name == "right") lidar.T_base_lidar = lidar.T_base_lidar * SE3::exp(shock);
  io::write_extrinsics(dir / "wrong.yaml", wrong);
  std::ofstream(dir / "check.yaml") << "extrinsic_check:\n  frames: 5\n";  // a verdict within the short drive
  const std::string common = "odometry --dataset " + quoted(sim.string()) + " --config " + quoted((dir / "check.yaml").string());

  const fs::path truth = dir / "truth";
  const CliResult right = run_cli(common + " --out " + quoted(truth.string()));
  ASSERT_EQ(right.exit_code, 0) << right.output;
  EXPECT_TRUE(nlohmann::json::parse(std::ifstream(truth / "metrics.json"))["extrinsic_check"].empty());

  const fs::path run = dir / "wrong";
  const CliResult result = run_cli(common + " --extrinsics " + quoted((dir / "wrong.yaml").string()) + " --out " + quoted(run.string()));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("warning: right: the given extrinsic disagrees with the map (at frame 5"), std::string::npos)
      << result.output;
  const auto check = nlohmann::json::parse(std::ifstream(run / "metrics.json"))["extrinsic_check"];
  ASSERT_EQ(check.size(), 1u) << check;
  EXPECT_EQ(check[0]["lidar"], "right");
  EXPECT_EQ(check[0]["disagreed_frame"].get<int>(), 5);  // frames 1-5 give the first median of 5 (frame 0 registers nothing)
  EXPECT_GT(check[0]["residual_ratio"].get<double>(), 2.0);

  // 0.1 m along each axis alone: the residual stays near the base's, the final map's points of the right LiDAR lie
  // far off the left's planes (the map test).
  io::write_extrinsics(dir / "shifted.yaml", perturbed_truth(sim, "right", 0.0, 0.1));
  const fs::path shifted_run = dir / "shifted";
  const CliResult by_map =
      run_cli(common + " --extrinsics " + quoted((dir / "shifted.yaml").string()) + " --out " + quoted(shifted_run.string()));
  EXPECT_EQ(by_map.exit_code, 1) << by_map.output;
  const auto map_check = nlohmann::json::parse(std::ifstream(shifted_run / "metrics.json"))["extrinsic_check"];
  ASSERT_EQ(map_check.size(), 1u) << map_check;
  EXPECT_TRUE(map_check[0]["residual_ratio"].is_null()) << map_check;
  EXPECT_GT(map_check[0]["map_ratio"].get<double>(), 3.0);
  EXPECT_EQ(map_check[0]["disagreed_frame"].get<int>(), kCheckFrames - 1);
}

// Real keyframes are rarely evenly spaced: --times gives each cloud its stamp
// (here BALM's own, from the reference file). The trajectory carries them, and
// a file that does not hold one increasing stamp per cloud is exit 3 naming it.
TEST(CliOdometry, ScanFolderTakesOneStampPerCloudFromTimes) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const fs::path balm = shared_data() / "real" / "balm_ouster";
  const Trajectory reference = io::read_balm_poses(balm / "alidarPose_0-49.csv");
  const fs::path frames = dir / "frames";
  fs::create_directories(frames);
  std::ofstream times(dir / "times.txt");
  times << "# BALM keyframes 20..25\n" << std::setprecision(17);
  for (int k = 20; k < 26; ++k) {
    const std::string name = "full" + std::to_string(k) + ".pcd";
    fs::copy_file(balm / "frames" / name, frames / name);
    times << reference.poses[static_cast<std::size_t>(k)].stamp << '\n';
  }
  times.close();
  const fs::path run = dir / "run";
  CliResult result = run_cli("odometry --scans " + quoted(frames.string()) + " --times " + quoted((dir / "times.txt").string()) +
                             " --out " + quoted(run.string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const Trajectory tum = io::read_tum(run / "trajectory.tum");
  ASSERT_EQ(tum.poses.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(tum.poses[i].stamp, reference.poses[20 + i].stamp, 1e-6) << "frame " << i;
  // The stamps are real (0.5 s +- jitter): the relative motion still follows the reference.
  const SE3 moved = tum.poses.front().T_world_base.inverse() * tum.poses.back().T_world_base;
  const SE3 truth = reference.poses[20].T_world_base.inverse() * reference.poses[25].T_world_base;
  EXPECT_LT((moved.inverse() * truth).translation().norm(), 0.05);

  std::ofstream(dir / "short.txt") << "0\n0.5\n1\n";
  result = run_cli("odometry --scans " + quoted(frames.string()) + " --times " + quoted((dir / "short.txt").string()) + " --out " +
                   quoted((dir / "run2").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("short.txt"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("3 stamps for 6 clouds"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(dir / "run2"));
  std::ofstream(dir / "unsorted.txt") << "0\n0.5\n1\n0.9\n2\n2.5\n";
  result = run_cli("odometry --scans " + quoted(frames.string()) + " --times " + quoted((dir / "unsorted.txt").string()) + " --out " +
                   quoted((dir / "run2").string()));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("line 4"), std::string::npos) << result.output;
  result = run_cli("odometry --scans " + quoted(frames.string()) + " --times " + quoted((dir / "short.txt").string()) +
                   " --period 0.5 --out " + quoted((dir / "run2").string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;  // --times excludes --period
}

}  // namespace
}  // namespace mlidar::test
