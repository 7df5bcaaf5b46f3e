// report.html of a hand-made run folder: the sections its data allow, the
// verdicts in words, the extrinsic errors against ground truth (computed here
// independently), nothing fetched, the same bytes for the same folder, and
// clear errors for folders that are no run.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/point_covariance_fields.hpp"
#include "mlidar/io/point_table.hpp"
#include "mlidar/io/pose_covariance_io.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/report/run_report.hpp"
#include "test_support.hpp"

namespace mlidar::report {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 20;

Trajectory straight_line(double speed, double offset_y) {
  Trajectory t;
  for (int i = 0; i < kFrames; ++i) t.poses.push_back({0.1 * i, SE3(Quat::Identity(), Vec3(speed * 0.1 * i, offset_y, 1.0))});
  return t;
}

nlohmann::json pose_json(const SE3& T) {
  const Quat q = T.rotation();
  return {{"translation", {T.translation().x(), T.translation().y(), T.translation().z()}},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

/// A slam-like run: `right` converged (windows from frame 5), `left` never started.
nlohmann::json slam_metrics(const SE3& T_right) {
  nlohmann::json metrics = {{"frames", kFrames},  {"calibrate", "online"}, {"lidars", {"top", "right", "left"}},
                            {"lost_frames", 1},   {"suspect_frames", 0},   {"convergence", {{"lambda_calib", 70.0}}},
                            {"map_restarts", {7}}};
  for (const char* stage : {"load", "odometry", "calibration"})
    metrics["stages"][stage] = {{"mean", 0.01}, {"p50", 0.01}, {"p95", 0.02}, {"max", 0.03}};
  metrics["total_seconds"] = {{"mean", 0.02}, {"p50", 0.02}, {"p95", 0.03}, {"max", 0.05}};
  nlohmann::json information = nlohmann::json::array();
  for (int i = 0; i < 36; ++i) information.push_back(i % 7 == 0 ? 1e6 : 0.0);  // sigma 1 mm / 1 mrad per axis
  for (int i = 0; i < kFrames; ++i) {
    nlohmann::json right = {{"lambda_min", i >= 5 ? nlohmann::json(10.0 * i) : nlohmann::json()}, {"accepted", i >= 8}};
    right["window_estimate"] = i >= 5 ? pose_json(T_right) : nlohmann::json();
    right["window_information"] = i >= 5 ? information : nlohmann::json();
    metrics["per_frame"].push_back({{"stamp", 100.0 + 0.1 * i},
                                    {"lidars", {{"right", right}, {"left", {{"lambda_min", nullptr}}}}},
                                    {"seconds", {{"load", 0.01}, {"odometry", 0.001 * i}, {"calibration", 0.002}}}});
  }
  nlohmann::json right = pose_json(T_right);
  right.update({{"role", "trusted"},
                {"converged_frame", 12},
                {"first_converged_frame", 12},
                {"accepted", 25},
                {"initialization", {{"state", "ready"}, {"frame", 4}, {"translation_start", "hand_eye"}}}});
  nlohmann::json left = pose_json(SE3::identity());
  left.update({{"role", "initializing"},
               {"converged_frame", nullptr},
               {"initialization", {{"state", "collecting"}, {"unobservable_from_motion", {"rotation and translation (3 motion pairs)"}}}}});
  metrics["per_lidar"] = {{"right", right}, {"left", left}, {"top", pose_json(SE3::identity())}};
  return metrics;
}

struct Fixture {
  fs::path run, dataset;
  SE3 T_right_truth, T_right_estimate;
};

Fixture make_run(bool with_run_json) {
  Fixture f;
  const fs::path dir = test::scratch_dir();
  f.run = dir / "run";
  f.dataset = dir / "sim";
  fs::create_directories(f.run);
  fs::create_directories(f.dataset / "groundtruth");
  f.T_right_truth = SE3(quat_from_rpy_deg(Vec3(40.0, 0.0, 0.0)), Vec3(0.0, -0.477, -0.22));
  // 1 deg about x and 2 cm along y off the truth.
  f.T_right_estimate = SE3(quat_from_rpy_deg(Vec3(41.0, 0.0, 0.0)), Vec3(0.0, -0.457, -0.22));
  io::Extrinsics estimate{"top",
                          {{"top", SE3::identity(), std::nullopt},
                           {"right", f.T_right_estimate, Mat6::Identity() * 1e-4},
                           {"left", SE3::identity(), std::nullopt}}};
  io::Extrinsics truth{
      "top", {{"top", SE3::identity(), std::nullopt}, {"right", f.T_right_truth, std::nullopt}, {"left", SE3::identity(), std::nullopt}}};
  io::write_extrinsics(f.run / "extrinsics.yaml", estimate);
  io::write_extrinsics(f.dataset / "groundtruth" / "extrinsics.yaml", truth);
  io::write_tum(f.run / "trajectory.tum", straight_line(1.0, 0.0));
  io::write_tum(f.dataset / "groundtruth" / "trajectory.tum", straight_line(1.02, 0.0));
  // Pose covariances growing as k (0.01 m)^2 per axis along x, y, z and k (0.1 deg)^2 in rotation.
  std::vector<io::StampedCovariance> covariances;
  for (int k = 0; k < kFrames; ++k) {
    Vec6 variances;
    variances << Vec3::Constant(1e-4 * k), Vec3::Constant(std::pow(deg_to_rad(0.1), 2) * k);
    covariances.push_back({0.1 * k, Mat6(variances.asDiagonal())});
  }
  io::write_pose_covariances(f.run / "pose_covariance.txt", covariances);
  std::ofstream(f.run / "metrics.json") << slam_metrics(f.T_right_estimate).dump();
  // A map: a 10 x 4 m floor at z = 0 and one post 2 m high at (5, 2).
  Scan map;
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 40; ++j) map.points.emplace_back(0.1f * i, 0.1f * j, 0.0f);
  for (int k = 0; k < 200; ++k) map.points.emplace_back(5.0f, 2.0f, 0.01f * k);
  io::write_cloud(f.run / "map.ply",
                  io::CloudFile{io::CloudFormat::kPly, "binary_little_endian", {0, 0, 0, 1, 0, 0, 0}, io::from_scan(map)});
  if (with_run_json)
    std::ofstream(f.run / "run.json") << nlohmann::json{
        {"tool", "mlidar"},
        {"command", "slam"},
        {"arguments", {"mlidar", "slam", "--dataset", f.dataset.string()}},
        {"started_utc", "2026-12-03T08:00:00Z"},
        {"finished_utc",
         "2026-12-03T08:00:10Z"}}.dump();
  return f;
}

std::string section(const std::string& html, const std::string& id) {
  const std::size_t start = html.find("<section id=\"" + id + "\">");
  if (start == std::string::npos) return {};
  return html.substr(start, html.find("</section>", start) - start);
}

TEST(RunReport, HasTheSectionsItsDataAllowWithVerdictsInWords) {
  const Fixture f = make_run(true);
  const RunData run = load_run(f.run);  // the dataset from run.json's --dataset
  ASSERT_TRUE(run.gt_trajectory && run.gt_extrinsics) << (run.notes.empty() ? "" : run.notes.front());
  const std::string html = render_report_html(run);
  for (const char* id : {"summary", "extrinsics", "trajectory", "map", "calibration-right", "timing"})
    EXPECT_FALSE(section(html, id).empty()) << id;
  EXPECT_TRUE(section(html, "calibration-left").empty()) << "no window, no calibration section";
  const std::string summary = section(html, "summary");
  EXPECT_NE(summary.find("<li class=\"ok\">right: calibrated online, converged at frame 12"), std::string::npos) << summary;
  EXPECT_NE(summary.find("<li class=\"bad\">left: not calibrated (initializing, collecting): rotation and translation (3 motion pairs)"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("<li class=\"bad\">1 frame(s) could not be registered"), std::string::npos) << summary;
  EXPECT_NE(summary.find("<li class=\"bad\">the local map was started again at frame(s) 7 after"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("top:"), std::string::npos) << "the base has no verdict";
  // Error against the truth, made 1 deg / 2 cm off above; NEES by hand: e^T (1e-4 I)^-1 e.
  const double nees = (0.02 * 0.02 + deg_to_rad(1.0) * deg_to_rad(1.0)) / 1e-4;
  const std::string extrinsics = section(html, "extrinsics");
  char expected[96];
  std::snprintf(expected, sizeof expected, "<td>1.000 / 2.00</td><td>%.2f</td>", nees);
  EXPECT_NE(extrinsics.find(expected), std::string::npos) << expected << "\n" << extrinsics;
  const std::string trajectory = section(html, "trajectory");
  EXPECT_NE(trajectory.find("ATE (SE(3)-aligned) RMSE"), std::string::npos);
  EXPECT_NE(trajectory.find("Pose uncertainty (1 sigma per axis)"), std::string::npos);
  char sigma[160];
  const double sd = 0.01 * std::sqrt(kFrames - 1.0);
  std::snprintf(sigma, sizeof sigma, "Pose 1&sigma; at the last frame: x %.3f m, y %.3f m, z %.3f m; rotation %.2f&deg;", sd, sd, sd,
                0.1 * std::sqrt(kFrames - 1.0));
  EXPECT_NE(trajectory.find(sigma), std::string::npos) << sigma << "\n" << trajectory.substr(trajectory.find("Pose 1"), 300);
  EXPECT_NE(trajectory.find("inside the 95 % NEES band"), std::string::npos);
  // The map: the floor in the lowest colour, the post's cell in the highest (heights clipped to the 2nd-98th percentile).
  const std::string map = section(html, "map");
  EXPECT_NE(map.find("4341 points"), std::string::npos) << map.substr(0, 300);
  EXPECT_NE(map.find("fill=\"#440154\""), std::string::npos) << "floor: the bottom of the scale";
  EXPECT_NE(map.find("fill=\"#fde725\""), std::string::npos) << "post: the top of the scale";
  EXPECT_EQ(html.find("http"), std::string::npos) << "nothing to fetch, no namespace URL either";
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(render_report_html(load_run(f.run)), html) << "the same folder gives the same bytes";
}

TEST(RunReport, AMapWithCovariancesIsAlsoDrawnByItsTrace) {
  const Fixture f = make_run(true);
  EXPECT_EQ(section(render_report_html(load_run(f.run)), "map").find("covariance trace"), std::string::npos) << "no covariances, no view";
  // A 10 x 4 m floor certain to 1e-4 m^2 and a far strip at x = 9-10 m uncertain to 1e-2 m^2.
  Scan map;
  std::vector<io::UpperCovariance> covariances;
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 40; ++j) {
      map.points.emplace_back(0.1f * i, 0.1f * j, 0.0f);
      const float variance = i > 90 ? 1e-2F / 3 : 1e-4F / 3;
      covariances.push_back({variance, 0.0F, 0.0F, variance, 0.0F, variance});
    }
  io::CloudFile cloud{io::CloudFormat::kPly, "binary_little_endian", {0, 0, 0, 1, 0, 0, 0}, io::from_scan(map)};
  io::add_point_covariances(cloud.table, covariances);
  fs::remove(f.run / "map.ply");
  io::write_cloud(f.run / "map.ply", cloud);
  const RunData run = load_run(f.run);
  ASSERT_EQ(run.map_traces.size(), map.points.size());
  EXPECT_NEAR(run.map_traces.back(), 1e-2, 1e-7);
  const std::string view = section(render_report_html(run), "map");
  const std::size_t words = view.find("largest tr(&Sigma;) in them"), at = view.find("largest point covariance trace");
  ASSERT_NE(words, std::string::npos);
  ASSERT_NE(at, std::string::npos);
  EXPECT_NE(view.find("from 0.0001 m&sup2;", words), std::string::npos) << view.substr(words, 400);
  EXPECT_NE(view.find("to 0.01 m&sup2;", words), std::string::npos);
  EXPECT_NE(view.find("fill=\"#440154\"", at), std::string::npos) << "the certain floor: the bottom of the scale";
  EXPECT_NE(view.find("fill=\"#fde725\"", at), std::string::npos) << "the uncertain strip: the top of the scale";
}

TEST(RunReport, WithoutGroundTruthItSaysSoAndStillRenders) {
  const Fixture f = make_run(false);
  const RunData run = load_run(f.run, {"slam", f.dataset / "elsewhere", {}});
  EXPECT_FALSE(run.gt_trajectory);
  ASSERT_EQ(run.notes.size(), 1u);
  EXPECT_NE(run.notes.front().find("no ground truth"), std::string::npos);
  const std::string html = render_report_html(run);
  EXPECT_NE(section(html, "summary").find("no ground truth"), std::string::npos);
  EXPECT_EQ(section(html, "trajectory").find("ATE"), std::string::npos);
  EXPECT_FALSE(section(html, "calibration-right").empty());
}

TEST(RunReport, AFolderThatIsNoRunIsABadInputNamingIt) {
  const fs::path dir = test::scratch_dir();
  EXPECT_THROW(load_run(dir / "missing"), InputError);
  fs::create_directories(dir / "plain");
  try {
    load_run(dir / "plain");
    FAIL() << "no run.json: not a run folder";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("run.json"), std::string::npos) << error.what();
  }
  const Fixture f = make_run(true);
  std::ofstream(f.run / "metrics.json") << "{ truncated";
  try {
    load_run(f.run);
    FAIL() << "a broken metrics.json";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("metrics.json"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace mlidar::report
