// The page of a one-pair calibration: the clouds overlaid before and after.
// Against a known transform: with the true extrinsic every target cell is a
// shared cell (green) and the shared area is far larger than from a wrong
// start; the numbers in the table are the transform's; the same input gives
// the same bytes; names are escaped.
#include <cmath>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "mlidar/core/conversions.hpp"
#include "mlidar/report/pair_report.hpp"

namespace mlidar::report {
namespace {

/// Three walls of a 6 m room corner and its floor, sampled every 5 cm, in the reference LiDAR's frame.
std::vector<Eigen::Vector3f> corner_room() {
  std::vector<Eigen::Vector3f> points;
  for (float a = 0.0F; a < 6.0F; a += 0.05F)
    for (float b = 0.0F; b < 2.5F; b += 0.05F) {
      points.emplace_back(a - 2.0F, 4.0F, b - 1.0F);          // wall facing -y
      points.emplace_back(4.0F, a - 2.0F, b - 1.0F);          // wall facing -x
      points.emplace_back(a - 2.0F, b * 2.4F - 2.0F, -1.0F);  // floor
    }
  return points;
}

/// Summed width (SVG units) of the rects of `fill` in the figure titled `title`.
double filled_width(const std::string& html, const std::string& title, const std::string& fill) {
  const std::size_t at = html.find("<title>" + title + "</title>");
  EXPECT_NE(at, std::string::npos) << title;
  if (at == std::string::npos) return 0.0;
  const std::string svg = html.substr(at, html.find("</svg>", at) - at);
  const std::regex rect("<rect [^>]*width=\"([0-9.]+)\"[^>]*fill=\"" + fill + "\"");
  double sum = 0.0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), rect); it != std::sregex_iterator(); ++it) sum += std::stod((*it)[1]);
  return sum;
}

PairCalibration example() {
  PairCalibration pair;
  pair.command = "calibrate refine";
  pair.ref_name = "roof";
  pair.target_name = "bumper<right>";
  pair.ref_file = "roof.pcd";
  pair.target_file = "bumper.pcd";
  pair.ref_points = corner_room();
  const SE3 T_ref_target(Quat(Eigen::AngleAxisd(deg_to_rad(10.0), Vec3::UnitZ())), Vec3(0.5, 0.2, 0.1));
  const SE3 T_target_ref = T_ref_target.inverse();
  for (const Eigen::Vector3f& p : pair.ref_points) pair.target_points.push_back((T_target_ref * Vec3(p.cast<double>())).cast<float>());
  pair.T_ref_target_before = SE3();
  pair.before_words = "identity";
  pair.T_ref_target = T_ref_target;
  Mat6 covariance = Mat6::Zero();
  covariance.diagonal() << 1e-4, 4e-4, 9e-4, 1e-6, 1e-6, 1e-6;
  pair.covariance = covariance;
  pair.verdict = "converged";
  return pair;
}

TEST(PairReport, TheTrueExtrinsicMakesTheCloudsShareTheirCells) {
  const std::string html = render_pair_calibration_html(example());
  for (const char* view : {"top view", "side view"}) {
    const double shared_before = filled_width(html, std::string("Before, ") + view, "#2ca02c");
    const double shared_after = filled_width(html, std::string("After, ") + view, "#2ca02c");
    const double target_only_after = filled_width(html, std::string("After, ") + view, "#ff7f0e");
    EXPECT_GT(shared_after, 2.0 * shared_before) << view;
    EXPECT_LT(target_only_after, 0.01 * shared_after) << view << ": the target lies on the reference's points";
    EXPECT_GT(filled_width(html, std::string("Before, ") + view, "#ff7f0e"), 0.2 * shared_after) << view << ": the start is off";
  }
}

TEST(PairReport, TablesHoldTheTransformAndItsSigmaAndNamesAreEscaped) {
  const std::string html = render_pair_calibration_html(example());
  EXPECT_NE(html.find("0.5000, 0.2000, 0.1000"), std::string::npos);
  EXPECT_TRUE(std::regex_search(html, std::regex(R"(-?0\.000, -?0\.000, 10\.000)"))) << "roll, pitch, yaw in degrees";
  EXPECT_NE(html.find("1.00 / 2.00 / 3.00"), std::string::npos) << "1-sigma in cm of the covariance's diagonal";
  EXPECT_NE(html.find("moved the start by 10.000&deg; and 0.5477 m"), std::string::npos);
  EXPECT_NE(html.find("bumper&lt;right&gt;"), std::string::npos);
  EXPECT_EQ(html.find("bumper<right>"), std::string::npos);
  EXPECT_EQ(html, render_pair_calibration_html(example()));
  EXPECT_EQ(html.find("http"), std::string::npos) << "nothing fetched";
}

}  // namespace
}  // namespace mlidar::report
