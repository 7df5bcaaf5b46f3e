// The page of a one-pair calibration (pair_report.hpp).
#include "mlidar/report/pair_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "mlidar/core/conversions.hpp"
#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

constexpr int kLongSideCells = 320;
constexpr const char* kRefColour = "#1f77b4";
constexpr const char* kTargetColour = "#ff7f0e";
constexpr const char* kBothColour = "#2ca02c";

/// The box both views show: the reference cloud's 2nd-98th percentile per axis, widened by a tenth (a few far
/// returns would otherwise shrink the overlap to a few cells).
struct Extent {
  Eigen::Vector3f lo, hi;
};

Extent extent_of(const std::vector<Eigen::Vector3f>& points) {
  Extent extent{Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones()};
  if (points.empty()) return extent;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> values;
    values.reserve(points.size());
    for (const Eigen::Vector3f& p : points) values.push_back(p(axis));
    const auto at = [&](double share) {
      const auto k = static_cast<std::size_t>(share * static_cast<double>(values.size() - 1));
      std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
      return values[k];
    };
    const float lo = at(0.02), hi = std::max(at(0.98), lo + 0.5F), margin = 0.1F * (hi - lo);
    extent.lo(axis) = lo - margin;
    extent.hi(axis) = hi + margin;
  }
  return extent;
}

/// Cells over (horizontal, vertical) of the extent: bit 1 a reference point, bit 2 a target point.
Raster overlay(const std::vector<Eigen::Vector3f>& ref, const std::vector<Eigen::Vector3f>& target_in_ref, const Extent& extent,
               int horizontal, int vertical) {
  Raster raster;
  const double width = extent.hi(horizontal) - extent.lo(horizontal), height = extent.hi(vertical) - extent.lo(vertical);
  raster.cell = std::max(std::max(width, height) / kLongSideCells, 0.01);
  raster.x0 = extent.lo(horizontal);
  raster.y0 = extent.lo(vertical);
  raster.columns = static_cast<int>(std::ceil(width / raster.cell));
  raster.rows = static_cast<int>(std::ceil(height / raster.cell));
  std::vector<unsigned char> owners(static_cast<std::size_t>(raster.columns) * raster.rows, 0);
  const auto mark = [&](const std::vector<Eigen::Vector3f>& points, unsigned char bit) {
    for (const Eigen::Vector3f& p : points) {
      const double c = (p(horizontal) - raster.x0) / raster.cell, r = (p(vertical) - raster.y0) / raster.cell;
      if (!(c >= 0 && r >= 0 && c < raster.columns && r < raster.rows)) continue;
      owners[static_cast<std::size_t>(r) * raster.columns + static_cast<std::size_t>(c)] |= bit;
    }
  };
  mark(ref, 1);
  mark(target_in_ref, 2);
  static const std::array<std::string, 4> kColours{"", kRefColour, kTargetColour, kBothColour};
  raster.colours.resize(owners.size());
  for (std::size_t i = 0; i < owners.size(); ++i) raster.colours[i] = kColours[owners[i]];
  return raster;
}

Chart overlay_chart(const std::string& title, Raster raster, int horizontal, int vertical) {
  Chart chart = spatial_view(title, horizontal, vertical);
  chart.raster = std::move(raster);
  return chart;
}

std::vector<Eigen::Vector3f> transformed(const SE3& T, const std::vector<Eigen::Vector3f>& points) {
  const Eigen::Matrix3f R = T.rotation().toRotationMatrix().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) out.push_back(R * p + t);
  return out;
}

std::vector<std::string> pose_row(const std::string& name, const SE3& T, const std::optional<Mat6>& covariance) {
  const Vec3 t = T.translation();
  const Vec3 rpy = rpy_deg_from_quat(T.rotation());
  std::vector<std::string> row{name, fixed(t.x(), 4) + ", " + fixed(t.y(), 4) + ", " + fixed(t.z(), 4),
                               fixed(rpy.x(), 3) + ", " + fixed(rpy.y(), 3) + ", " + fixed(rpy.z(), 3), "-", "-"};
  if (covariance) {
    const auto sd = [&](int i) { return std::sqrt(std::max(0.0, (*covariance)(i, i))); };
    row[3] = fixed(100 * sd(0), 2) + " / " + fixed(100 * sd(1), 2) + " / " + fixed(100 * sd(2), 2);
    row[4] = fixed(rad_to_deg(sd(3)), 3) + " / " + fixed(rad_to_deg(sd(4)), 3) + " / " + fixed(rad_to_deg(sd(5)), 3);
  }
  return row;
}

Section summary(const PairCalibration& pair) {
  std::ostringstream html;
  html << "<ul class=\"verdicts\">\n<li class=\"" << escape_markup(pair.verdict_level) << "\">" << escape_markup(pair.verdict) << "</li>\n";
  for (const std::string& reason : pair.reasons) html << "<li class=\"warn\">" << escape_markup(reason) << "</li>\n";
  html << "</ul>\n";
  std::vector<std::vector<std::string>> rows{{"reference", escape_markup(pair.ref_name + " (" + pair.ref_file + ")")},
                                             {"target", escape_markup(pair.target_name + " (" + pair.target_file + ")")}};
  for (const auto& [what, value] : pair.facts) rows.push_back({escape_markup(what), escape_markup(value)});
  html << html_table({"", ""}, rows);
  const SE3 change = pair.T_ref_target_before.inverse() * pair.T_ref_target;
  html << "<p>T_ref_target (p_ref = R p_target + t): the result moved the start by "
       << fixed(rad_to_deg(so3_log(change.rotation()).norm()), 3) << "&deg; and "
       << fixed((pair.T_ref_target.translation() - pair.T_ref_target_before.translation()).norm(), 4) << " m.</p>\n"
       << html_table({"", "translation (m)", "roll, pitch, yaw (deg)", "1&sigma; x / y / z (cm)", "1&sigma; rotation (deg)"},
                     {pose_row("before: " + escape_markup(pair.before_words), pair.T_ref_target_before, std::nullopt),
                      pose_row("after", pair.T_ref_target, pair.covariance)});
  return {"summary", "Summary", html.str()};
}

Section overlay_section(const PairCalibration& pair) {
  const Extent extent = extent_of(pair.ref_points);
  const std::vector<Eigen::Vector3f> before = transformed(pair.T_ref_target_before, pair.target_points);
  const std::vector<Eigen::Vector3f> after = transformed(pair.T_ref_target, pair.target_points);
  std::ostringstream html;
  html << "<p>Both clouds in the frame of <b>" << escape_markup(pair.ref_name) << "</b>, cells of the reference cloud's central box: "
       << "<span style=\"color:" << kRefColour << "\">blue</span> only " << escape_markup(pair.ref_name)
       << ", <span style=\"color:" << kTargetColour << "\">orange</span> only " << escape_markup(pair.target_name)
       << ", <span style=\"color:" << kBothColour << "\">green</span> both. Aligned clouds turn the shared structure green.</p>\n"
       << "<div class=\"figures\">\n"
       << render_svg(overlay_chart("Before, top view", overlay(pair.ref_points, before, extent, 0, 1), 0, 1))
       << render_svg(overlay_chart("After, top view", overlay(pair.ref_points, after, extent, 0, 1), 0, 1))
       << render_svg(overlay_chart("Before, side view", overlay(pair.ref_points, before, extent, 0, 2), 0, 2))
       << render_svg(overlay_chart("After, side view", overlay(pair.ref_points, after, extent, 0, 2), 0, 2)) << "</div>\n";
  return {"overlay", "Clouds overlaid", html.str()};
}

}  // namespace

std::string render_pair_calibration_html(const PairCalibration& pair) {
  return render_page("mlidar " + pair.command + ": " + pair.target_name + " to " + pair.ref_name, {summary(pair), overlay_section(pair)});
}

}  // namespace mlidar::report
