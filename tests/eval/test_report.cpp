// JSON keys (a public interface) and the SVG plot's structure.
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "eval_test_support.hpp"
#include "mlidar/eval/report.hpp"
#include "mlidar/eval/svg_plot.hpp"

namespace mlidar::eval {
namespace {

TEST(Report, TrajectoryJsonHasTheDocumentedKeys) {
  const Trajectory gt = test::wavy_trajectory(50);
  const TrajectoryReport report = evaluate_trajectory(gt, gt, TrajectoryEvalOptions{}, "gt", "est");
  const nlohmann::json json = to_json(report);
  for (const char* key : {"gt_poses", "est_poses", "matched_poses", "alignment", "ate", "rpe", "kitti"})
    EXPECT_TRUE(json.contains(key)) << key;
  EXPECT_EQ(json["matched_poses"], 50);
  EXPECT_EQ(json["alignment"]["mode"], "se3");
  for (const char* key : {"count", "rmse", "mean", "median", "std", "min", "max"})
    EXPECT_TRUE(json["ate"]["translation_m"].contains(key)) << key;
  EXPECT_TRUE(json["rpe"].contains("translation_percent"));
  EXPECT_TRUE(json["kitti"].is_null());
  EXPECT_NE(format_table(report).find("ATE trans (m)"), std::string::npos);
}

TEST(Report, MissingValuesAreNull) {
  const nlohmann::json json = to_json(summarize({}));
  EXPECT_EQ(json["count"], 0);
  EXPECT_TRUE(json["rmse"].is_null());
  MapMetrics empty;
  empty.mean_map_entropy = empty.mean_plane_variance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(to_json(empty, MapMetricsOptions{})["mean_map_entropy"].is_null());
}

TEST(Report, CalibrationJson) {
  ExtrinsicError error;
  error.name = "top";
  error.nees = 20.0;
  const nlohmann::json json = to_json(std::vector<ExtrinsicError>{error, ExtrinsicError{}});
  EXPECT_EQ(json["lidars"][0]["name"], "top");
  EXPECT_EQ(json["lidars"][0]["nees_within_95"], false);
  EXPECT_TRUE(json["lidars"][1]["nees"].is_null());
  EXPECT_TRUE(json["lidars"][1]["nees_within_95"].is_null());
}

TEST(SvgPlot, ThreeLinesWithOneVertexPerPose) {
  const Trajectory gt = test::wavy_trajectory(120);
  const TrajectoryReport report = evaluate_trajectory(gt, gt, TrajectoryEvalOptions{}, "gt", "est");
  const std::string svg = trajectory_plot_svg(report.gt, report.est_aligned, report.stamps, report.ate.translation_errors_m);
  EXPECT_EQ(svg.rfind("<svg", 0), 0U);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  const std::regex polyline("<polyline[^>]*points=\"([^\"]*)\"");
  std::size_t lines = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), polyline); it != std::sregex_iterator(); ++it) {
    const std::string points = (*it)[1];
    const std::regex vertex("(-?[0-9.e+-]+),(-?[0-9.e+-]+) ");
    std::size_t vertices = 0;
    for (auto v = std::sregex_iterator(points.begin(), points.end(), vertex); v != std::sregex_iterator(); ++v) {
      const double x = std::stod((*v)[1]);
      const double y = std::stod((*v)[2]);
      EXPECT_TRUE(x >= 0 && x <= 1000 && y >= 0 && y <= 500) << x << "," << y;
      ++vertices;
    }
    EXPECT_EQ(vertices, 120U);
    ++lines;
  }
  EXPECT_EQ(lines, 3U);
}

}  // namespace
}  // namespace mlidar::eval
