// `mlidar detect train|run` from the command line: the files a user scripts against, and the exit codes of bad input.
// Without LibTorch (MLIDAR_WITH_DETECT off) the commands must say how to get them.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

#if MLIDAR_WITH_DETECT

/// A tiny cars dataset (the test's own scratch folder).
fs::path cars(const fs::path& dir, int frames) {
  const CliResult r = run_cli("simulate detection --scene cars --frames " + std::to_string(frames) + " --seed 5 --out " + quoted((dir / "cars").string()));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return dir / "cars";
}

fs::path tiny_config(const fs::path& dir) {
  std::ofstream(dir / "tiny.yaml") << "grid: {x_min: -38.4, x_max: 38.4, y_min: -38.4, y_max: 38.4}\nnetwork: {channels: 8}\nthreads: 1\n"
                                      "inference: {score_threshold: 0.0}\n";
  return dir / "tiny.yaml";
}

TEST(CliDetect, TrainsAndRunsIntoTheDocumentedFiles) {
  const fs::path dir = scratch_dir();
  const fs::path data = cars(dir, 2);
  const fs::path model = dir / "model";
  CliResult r = run_cli("detect train --data " + quoted(data.string()) + " --config " + quoted(tiny_config(dir).string()) +
                        " --fusion feature --max-steps 3 --out " + quoted(model.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* file : {"model.json", "detect.yaml", "stage1.pt", "stage2.pt", "training.json", "train_log.jsonl", "loss.svg"}) {
    EXPECT_TRUE(fs::exists(model / file)) << file;
  }
  const nlohmann::json info = nlohmann::json::parse(read_text(model / "model.json"));
  EXPECT_EQ(info["fusion"], "feature");
  EXPECT_EQ(info["stages"], nlohmann::json::array({1, 2}));
  r = run_cli("detect run --model " + quoted(model.string()) + " --dataset " + quoted(data.string()) + " --alpha 0.04 --out " +
              quoted((dir / "pred").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "pred" / "label_2" / "000000.txt"));
  EXPECT_TRUE(fs::exists(dir / "pred" / "label_2" / "000001.txt"));
  const nlohmann::json metrics = nlohmann::json::parse(read_text(dir / "pred" / "metrics.json"));
  EXPECT_EQ(metrics["frames"], 2);
  EXPECT_EQ(metrics["alpha"], 0.04);
  ASSERT_EQ(metrics["per_frame"].size(), 2U);
  EXPECT_GT(metrics["per_frame"][0]["stage1_ms"].get<double>(), 0.0);
  EXPECT_GT(metrics["per_frame"][0]["stage2_ms"].get<double>(), 0.0);
  EXPECT_EQ(metrics["refine_extrinsics"], false);
  EXPECT_TRUE(metrics["online_calibration"].is_null());
  // The predictions are label_2 lines with a score: eval detections reads them.
  r = run_cli("eval detections --gt " + quoted(data.string()) + " --pred " + quoted((dir / "pred").string()) + " --classes car");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // Online calibration first: both other LiDARs registered in both frames, their errors against the truth reported.
  r = run_cli("detect run --model " + quoted(model.string()) + " --dataset " + quoted(data.string()) +
              " --alpha 0.1 --refine-extrinsics --out " + quoted((dir / "pred_oc").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json oc = nlohmann::json::parse(read_text(dir / "pred_oc" / "metrics.json"));
  EXPECT_EQ(oc["refine_extrinsics"], true);
  const nlohmann::json& online = oc["online_calibration"];
  EXPECT_EQ(online["registrations"], 4);
  ASSERT_EQ(online["lidars"].size(), 2U);
  for (const auto& lidar : online["lidars"]) {
    SCOPED_TRACE(lidar.dump());
    EXPECT_EQ(lidar["registrations"], 2);
    EXPECT_LT(lidar["rotation_error_deg"]["used"]["max"].get<double>(), lidar["rotation_error_deg"]["given"]["max"].get<double>());
  }
}

TEST(CliDetect, BadInputExitsWithTheReason) {
  const fs::path dir = scratch_dir();
  const fs::path data = cars(dir, 1);
  const std::string config = " --config " + quoted(tiny_config(dir).string());
  // A dataset without labels cannot train: exit 3 naming label_2.
  fs::create_directories(dir / "unlabelled");
  fs::copy(data, dir / "unlabelled", fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  fs::remove_all(dir / "unlabelled" / "groundtruth" / "label_2");
  CliResult r = run_cli("detect train --data " + quoted((dir / "unlabelled").string()) + config + " --out " + quoted((dir / "m0").string()));
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("label_2"), std::string::npos) << r.output;
  // --fusion none without --lidar: exit 2 listing the LiDARs.
  r = run_cli("detect train --data " + quoted(data.string()) + config + " --fusion none --out " + quoted((dir / "m1").string()));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("front_left"), std::string::npos) << r.output;
  // A model folder whose detect.yaml was changed after training: exit 3.
  const fs::path model = dir / "m2";
  r = run_cli("detect train --data " + quoted(data.string()) + config + " --stage 1 --max-steps 1 --out " + quoted(model.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::string yaml = read_text(model / "detect.yaml");
  yaml.replace(yaml.find("channels: 8"), 11, "channels: 9");
  std::ofstream(model / "detect.yaml") << yaml;
  r = run_cli("detect run --model " + quoted(model.string()) + " --dataset " + quoted(data.string()) + " --out " + quoted((dir / "p").string()));
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("not the one the weights were trained with"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "p"));
  // Training again into it without --resume: exit 2, the folder unchanged.
  r = run_cli("detect train --data " + quoted(data.string()) + config + " --stage 1 --out " + quoted(model.string()));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--resume"), std::string::npos) << r.output;
  EXPECT_EQ(read_text(model / "detect.yaml"), yaml);
}

TEST(CliDetect, MlidarItselfDoesNotLoadLibTorch) {
  // Every other command would pay LibTorch's start-up (about a second); detect's jobs run in mlidar-detect.
  const std::string mlidar = read_text(mlidar_bin());
  ASSERT_FALSE(mlidar.empty()) << mlidar_bin();
  EXPECT_EQ(mlidar.find("libtorch_cpu.so"), std::string::npos);
  EXPECT_EQ(mlidar.find("libc10.so"), std::string::npos);
  const std::string helper = read_text(fs::path(mlidar_bin()).parent_path() / "mlidar-detect");
  EXPECT_NE(helper.find("libtorch_cpu.so"), std::string::npos);
}

TEST(CliDetect, WithoutMlidarDetectBesideItSaysWhereItLooked) {
  const fs::path dir = scratch_dir();
  const fs::path lone = dir / "bin" / "mlidar";
  fs::create_directories(lone.parent_path());
  fs::copy_file(mlidar_bin(), lone);
  // The command line is still checked (and its help shown) by mlidar alone.
  CliResult r = run_shell(quoted(lone.string()) + " detect run --help");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--refine-extrinsics"), std::string::npos) << r.output;
  r = run_shell(quoted(lone.string()) + " detect run --model m --dataset d --alpha 2 --out p");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--alpha"), std::string::npos) << r.output;
  r = run_shell(quoted(lone.string()) + " detect run --model m --dataset d --out " + quoted((dir / "p").string()));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("mlidar-detect"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find((dir / "bin" / "mlidar-detect").string()), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "p"));
}

#else

TEST(CliDetect, WithoutLibTorchSaysHowToGetIt) {
  const CliResult r = run_cli("detect run --model m --dataset d --out p");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("libtorch-dev"), std::string::npos) << r.output;
  GTEST_SKIP() << "MLOD's networks are not built (MLIDAR_WITH_DETECT off: LibTorch not found); only the message was checked";
}

#endif

}  // namespace
}  // namespace mlidar::test
