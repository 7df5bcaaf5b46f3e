// End-to-end `mlidar eval detections`: folder layouts, AP in the JSON, the PR plot, and exit 3 naming the file and
// line for each bad input (nothing written then).
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "apps/cli_runner.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

const std::string kCarAt10 = "car 0 0 -10 -1 -1 -1 -1 1.5 1.8 4.4 10 0 -1.7 0.3";
const std::string kCarAt15 = "Car 0 0 -10 -1 -1 -1 -1 1.5 1.8 4.4 0 15 -1.7 1.2";
const std::string kPedestrianAt8 = "pedestrian 0 0 -10 -1 -1 -1 -1 1.8 0.6 0.5 -8 2 -1.7 0";

/// A `simulate detection`-like ground truth (DIR/groundtruth/label_2 + labels) of two frames, three objects: two
/// cars in frame 0, a pedestrian no LiDAR hit in frame 1.
fs::path ground_truth_dataset(const fs::path& dir) {
  write_text(dir / "groundtruth/label_2/000000.txt", kCarAt10 + "\n" + kCarAt15 + "\n");
  write_text(dir / "groundtruth/label_2/000001.txt", kPedestrianAt8 + "\n");
  write_text(dir / "groundtruth/labels/000000.json",
             R"({"frame": "000000", "objects": [{"class": "car", "points_total": 90}, {"class": "car", "points_total": 12}]})");
  write_text(dir / "groundtruth/labels/000001.json", R"({"frame": "000001", "objects": [{"class": "pedestrian", "points_total": 0}]})");
  return dir;
}

std::string eval_command(const fs::path& gt, const fs::path& pred) {
  return "eval detections --gt " + quoted(gt.string()) + " --pred " + quoted(pred.string());
}

TEST(CliEvalDetections, OneOfTwoCarsFoundGivesHalfRecallAtFullPrecision) {
  const fs::path dir = scratch_dir();
  const fs::path dataset = ground_truth_dataset(dir / "data");
  // Frame 0: the car at 10 m found (0.9), a false positive at 40 m below it (0.4); frame 1: the pedestrian no
  // point lies on is detected (ignored: neither true nor false positive).
  write_text(dir / "pred/000000.txt", kCarAt10 + " 0.9\ncar 0 0 -10 -1 -1 -1 -1 1.5 1.8 4.4 -40 0 -1.7 0 0.4\n");
  write_text(dir / "pred/000001.txt", kPedestrianAt8 + " 0.8\n");
  const CliResult result = run_cli(eval_command(dataset, dir / "pred") + " --json " + quoted((dir / "ap.json").string()) + " --plot " +
                                   quoted((dir / "pr.svg").string()));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("car        hard"), std::string::npos) << result.output;
  const nlohmann::json json = nlohmann::json::parse(std::ifstream(dir / "ap.json"));
  EXPECT_EQ(json["frames"], 2);
  const nlohmann::json& car = json["classes"]["car"];
  EXPECT_EQ(car["ground_truths"], 2);
  EXPECT_EQ(car["predictions"], 2);
  EXPECT_DOUBLE_EQ(car["strict"]["iou"].get<double>(), 0.7);
  // Easy (< 20 m) and moderate: both cars, one found first: p_interp = 1 up to recall 1/2: R40 20/40, R11 6/11.
  // The 40 m false positive lies beyond those ranges (ignored); hard counts it, after the true positive: no change.
  for (const char* difficulty : {"easy", "moderate", "hard"}) {
    const nlohmann::json& ap = car["strict"][difficulty]["3d"];
    EXPECT_DOUBLE_EQ(ap["ap_r40"].get<double>(), 50.0) << difficulty;
    EXPECT_NEAR(ap["ap_r11"].get<double>(), 600.0 / 11.0, 1e-9) << difficulty;
    EXPECT_EQ(ap["true_positives"], 1) << difficulty;
    EXPECT_EQ(ap["precision_r40"].size(), 40U);
  }
  EXPECT_EQ(car["strict"]["easy"]["3d"]["false_positives"], 0);
  EXPECT_EQ(car["strict"]["hard"]["3d"]["false_positives"], 1);
  // The pedestrian without points is no ground truth: AP null, its detection no false positive.
  EXPECT_TRUE(json["classes"]["pedestrian"]["strict"]["easy"]["3d"]["ap_r40"].is_null());
  EXPECT_EQ(json["classes"]["pedestrian"]["strict"]["easy"]["3d"]["false_positives"], 0);
  EXPECT_EQ(json["mean"]["strict"]["easy"]["classes"], 1);
  std::ifstream svg(dir / "pr.svg");
  std::string first_line;
  std::getline(svg, first_line);
  EXPECT_EQ(first_line.rfind("<svg", 0), 0U);

  // --classes and --iou: cars only, at IoU 0.5 as the strict threshold.
  const CliResult cars = run_cli(eval_command(dataset / "groundtruth", dir / "pred") + " --classes car --iou car=0.5 --json " +
                                 quoted((dir / "cars.json").string()));
  ASSERT_EQ(cars.exit_code, 0) << cars.output;
  const nlohmann::json cars_json = nlohmann::json::parse(std::ifstream(dir / "cars.json"));
  EXPECT_FALSE(cars_json["classes"].contains("pedestrian"));
  EXPECT_DOUBLE_EQ(cars_json["classes"]["car"]["strict"]["iou"].get<double>(), 0.5);
}

TEST(CliEvalDetections, BadInputExitsThreeNamingFileAndLine) {
  const fs::path dir = scratch_dir();
  const fs::path dataset = ground_truth_dataset(dir / "data");
  const std::string good_frame_1 = kPedestrianAt8 + " 0.8\n";
  const struct {
    const char* name;
    std::string frame_0;
    std::string expected;
  } cases[] = {
      {"nan_size", kCarAt10 + " 0.9\ncar 0 0 -10 -1 -1 -1 -1 nan 1.8 4.4 10 0 -1.7 0.3 0.5\n", "line 2 column 9 (height)"},
      {"negative_size", "car 0 0 -10 -1 -1 -1 -1 1.5 -1.8 4.4 10 0 -1.7 0.3 0.5\n", "line 1 column 10 (width)"},
      {"unknown_class", "\n\ntruck 0 0 -10 -1 -1 -1 -1 1.5 1.8 4.4 10 0 -1.7 0.3 0.5\n", "line 3 column 1 (type)"},
      {"no_score", kCarAt10 + "\n", "line 1 column 16 (score)"},
  };
  for (const auto& bad : cases) {
    const fs::path pred = dir / bad.name;
    write_text(pred / "000000.txt", bad.frame_0);
    write_text(pred / "000001.txt", good_frame_1);
    const fs::path json = dir / (std::string(bad.name) + ".json");
    const CliResult result = run_cli(eval_command(dataset, pred) + " --json " + quoted(json.string()));
    EXPECT_EQ(result.exit_code, 3) << bad.name << ": " << result.output;
    EXPECT_NE(result.output.find((pred / "000000.txt").string()), std::string::npos) << bad.name << ": " << result.output;
    EXPECT_NE(result.output.find(bad.expected), std::string::npos) << bad.name << ": " << result.output;
    EXPECT_FALSE(fs::exists(json)) << bad.name;
  }
  // Ground truth is checked the same way.
  write_text(dir / "bad_gt/label_2/000000.txt", "car 0 0 -10 -1 -1 -1 -1 1.5 1.8 0 10 0 -1.7 0.3\n");
  write_text(dir / "bad_gt/label_2/000001.txt", "");
  write_text(dir / "nan_size/000001.txt", "");
  CliResult result = run_cli(eval_command(dir / "bad_gt", dir / "no_score"));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("line 1 column 11 (length)"), std::string::npos) << result.output;

  // Frame ids that do not pair up: a prediction file without ground truth, a ground-truth frame without predictions.
  write_text(dir / "extra/000000.txt", "");
  write_text(dir / "extra/000001.txt", "");
  write_text(dir / "extra/000002.txt", "");
  result = run_cli(eval_command(dataset, dir / "extra"));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("000002.txt"), std::string::npos) << result.output;
  write_text(dir / "missing/000001.txt", "");
  result = run_cli(eval_command(dataset, dir / "missing"));
  EXPECT_EQ(result.exit_code, 3) << result.output;
  EXPECT_NE(result.output.find("000000"), std::string::npos) << result.output;

  // labels/*.json that disagrees with label_2.
  write_text(dir / "data/groundtruth/labels/000001.json", R"({"objects": []})");
  result = run_cli(eval_command(dataset, dir / "extra"));
  EXPECT_EQ(result.exit_code, 3) << result.output;
}

TEST(CliEvalDetections, UsageErrorsExitTwo) {
  const fs::path dir = scratch_dir();
  const fs::path dataset = ground_truth_dataset(dir / "data");
  write_text(dir / "pred/000000.txt", "");
  write_text(dir / "pred/000001.txt", "");
  const std::string command = eval_command(dataset, dir / "pred");
  EXPECT_EQ(run_cli(command + " --classes car,truck").exit_code, 2);
  EXPECT_EQ(run_cli(command + " --classes car,car").exit_code, 2);
  EXPECT_EQ(run_cli(command + " --iou car=1.5").exit_code, 2);
  EXPECT_EQ(run_cli(command + " --iou car").exit_code, 2);
  EXPECT_EQ(run_cli(command + " --json " + quoted((dir / "no/such/folder/ap.json").string())).exit_code, 2);
  EXPECT_EQ(run_cli("eval detections --gt " + quoted(dataset.string())).exit_code, 2);
}

}  // namespace
}  // namespace mlidar::test
