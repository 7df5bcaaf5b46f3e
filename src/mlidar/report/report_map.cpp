// The map section of report.html: map.ply seen from above, each cell of a
// grid coloured by the highest point in it (heights clipped to the 2nd-98th
// percentile so a few stray points do not wash out the colours); when the map
// carries point covariances, a second view coloured by the largest tr(Sigma)
// in each cell (log scale, clipped likewise); when it says which LiDAR saw
// each point, a third view with each cell in its main LiDAR's colour.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

constexpr int kLongSideCells = 320;  ///< cells along the map's longer side
constexpr int kColourLevels = 24;    ///< heights are binned so runs of one colour merge into one rect

/// A perceptually ordered dark-blue to yellow scale (anchors of viridis), t in [0, 1].
std::string height_colour(double t) {
  static constexpr std::array<std::array<double, 3>, 5> kAnchors{
      {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
  const double at = std::clamp(t, 0.0, 1.0) * (kAnchors.size() - 1);
  const auto i = std::min<std::size_t>(static_cast<std::size_t>(at), kAnchors.size() - 2);
  const double f = at - static_cast<double>(i);
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x",
                static_cast<int>(std::lround(kAnchors[i][0] + f * (kAnchors[i + 1][0] - kAnchors[i][0]))),
                static_cast<int>(std::lround(kAnchors[i][1] + f * (kAnchors[i + 1][1] - kAnchors[i][1]))),
                static_cast<int>(std::lround(kAnchors[i][2] + f * (kAnchors[i + 1][2] - kAnchors[i][2]))));
  return text;
}

double percentile(std::vector<float> values, double share) {
  const auto k = static_cast<std::size_t>(share * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// The cells of a grid over `points` (x, y), each holding the largest `values` of its points mapped through
/// `level` (t in [0, 1]) onto the colour scale.
Raster top_view(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& values, const std::function<double(float)>& level) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Raster raster;
  raster.cell = std::max(static_cast<double>(std::max(hi.x() - lo.x(), hi.y() - lo.y())) / kLongSideCells, 0.05);
  raster.x0 = lo.x();
  raster.y0 = lo.y();
  raster.columns = static_cast<int>(std::floor((hi.x() - lo.x()) / raster.cell)) + 1;
  raster.rows = static_cast<int>(std::floor((hi.y() - lo.y()) / raster.cell)) + 1;
  std::vector<float> top(static_cast<std::size_t>(raster.columns) * raster.rows, -std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int c = std::min(raster.columns - 1, static_cast<int>((points[i].x() - raster.x0) / raster.cell));
    const int r = std::min(raster.rows - 1, static_cast<int>((points[i].y() - raster.y0) / raster.cell));
    float& cell = top[static_cast<std::size_t>(r) * raster.columns + c];
    cell = std::max(cell, values[i]);
  }
  raster.colours.resize(top.size());
  for (std::size_t i = 0; i < top.size(); ++i) {
    if (!std::isfinite(top[i])) continue;
    raster.colours[i] = height_colour(std::round(std::clamp(level(top[i]), 0.0, 1.0) * (kColourLevels - 1)) / (kColourLevels - 1));
  }
  return raster;
}

Chart top_view_chart(std::string title, Raster raster, const RunData& run) {
  Chart chart;
  chart.title = std::move(title);
  chart.x_label = "x (m)";
  chart.y_label = "y (m)";
  chart.equal_axes = true;
  chart.width = 900;
  chart.height = 640;
  chart.raster = std::move(raster);
  if (run.trajectory) {  // the estimate as written, in the map's frame
    Series path{"trajectory", "#ff3030", {}, {}};
    for (const StampedPose& pose : run.trajectory->poses) {
      path.x.push_back(pose.T_world_base.translation().x());
      path.y.push_back(pose.T_world_base.translation().y());
    }
    chart.series.push_back(std::move(path));
  }
  return chart;
}

/// The second view: each cell's largest tr(Sigma), log10 between the 2nd and 98th percentile.
std::string trace_view(const RunData& run) {
  std::vector<float> logs;
  for (const float trace : run.map_traces) logs.push_back(std::log10(std::max(trace, 1e-12F)));
  const double lo = percentile(logs, 0.02), hi = std::max(percentile(logs, 0.98), lo + 1e-3);
  const Chart chart = top_view_chart("Map, top view (largest point covariance trace per cell)",
                                     top_view(run.map, logs, [&](float v) { return (v - lo) / (hi - lo); }), run);
  char range[96];
  std::snprintf(range, sizeof range, "from %.2g m&sup2; (<span style=\"color:%s\">dark blue</span>) to %.2g m&sup2;", std::pow(10.0, lo),
                height_colour(0.0).c_str(), std::pow(10.0, hi));
  return "<p>Each point's position covariance &Sigma; (uncertainty-aware mapping): cells coloured by the largest tr(&Sigma;) in them, " +
         std::string(range) +
         " (<span style=\"color:#b8a000\">yellow</span>), log scale; points above the threshold w never entered the map.</p>\n" +
         render_svg(chart);
}

/// Distinct colours for up to eight LiDARs (Tableau's, without its red: the trajectory is red), grey for an unknown or a ninth.
const char* lidar_colour(std::size_t index) {
  static constexpr std::array<const char*, 8> kColours{"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd",
                                                       "#8c564b", "#e377c2", "#17becf", "#bcbd22"};
  return index < kColours.size() ? kColours[index] : "#7f7f7f";
}

/// The third view: each cell in the colour of the LiDAR with the most points in it (metrics.json "lidars" names them).
std::string lidar_view(const RunData& run) {
  std::vector<std::string> names;
  if (run.metrics.contains("lidars") && run.metrics["lidars"].is_array())
    for (const auto& name : run.metrics["lidars"]) names.push_back(name.is_string() ? name.get<std::string>() : "?");
  Raster raster = top_view(run.map, std::vector<float>(run.map.size(), 0.0F), [](float) { return 0.0; });  // the grid only
  std::vector<std::array<std::uint32_t, 9>> counts(raster.colours.size(), std::array<std::uint32_t, 9>{});
  std::vector<std::size_t> totals(9, 0);
  for (std::size_t i = 0; i < run.map.size(); ++i) {
    const int c = std::min(raster.columns - 1, static_cast<int>((run.map[i].x() - raster.x0) / raster.cell));
    const int r = std::min(raster.rows - 1, static_cast<int>((run.map[i].y() - raster.y0) / raster.cell));
    const std::size_t lidar = std::min<std::size_t>(run.map_lidars[i], 8);
    ++counts[static_cast<std::size_t>(r) * raster.columns + c][lidar];
    ++totals[lidar];
  }
  for (std::size_t cell = 0; cell < counts.size(); ++cell) {
    const auto most = std::max_element(counts[cell].begin(), counts[cell].end());
    raster.colours[cell] = *most == 0 ? std::string{} : std::string(lidar_colour(static_cast<std::size_t>(most - counts[cell].begin())));
  }
  std::vector<std::vector<std::string>> rows;
  for (std::size_t lidar = 0; lidar < totals.size(); ++lidar) {
    if (totals[lidar] == 0) continue;
    const std::string name = lidar < 8 && lidar < names.size() ? names[lidar] : "unknown";
    rows.push_back({"<span style=\"color:" + std::string(lidar_colour(lidar)) + "\">&#9632;</span> " + escape_markup(name),
                    std::to_string(totals[lidar]),
                    fixed(100.0 * static_cast<double>(totals[lidar]) / static_cast<double>(run.map.size()), 1)});
  }
  return "<p>Which LiDAR each part of the map comes from: cells in the colour of the LiDAR with the most points in them.</p>\n" +
         html_table({"LiDAR", "map points", "share (%)"}, rows) +
         render_svg(top_view_chart("Map, top view (the LiDAR with the most points per cell)", std::move(raster), run));
}

}  // namespace

std::optional<Section> map_section(const RunData& run) {
  std::vector<Eigen::Vector3f> points;
  for (const Eigen::Vector3f& p : run.map)
    if (p.allFinite()) points.push_back(p);
  if (points.size() < 10) return std::nullopt;
  std::vector<float> heights;
  for (const Eigen::Vector3f& p : points) heights.push_back(p.z());
  const double z_lo = percentile(heights, 0.02), z_hi = std::max(percentile(heights, 0.98), z_lo + 1e-3);
  const Chart chart = top_view_chart("Map, top view (highest point per cell)",
                                     top_view(points, heights, [&](float z) { return (z - z_lo) / (z_hi - z_lo); }), run);
  std::string html = "<p>map.ply, " + std::to_string(points.size()) + " points in the frame of trajectory.tum (drawn in red); cells of " +
                     fixed(chart.raster.cell, 2) + " m coloured by height from " + fixed(z_lo, 2) +
                     " m (<span style=\"color:" + height_colour(0.0) + "\">dark blue</span>) to " + fixed(z_hi, 2) +
                     " m (<span style=\"color:#b8a000\">yellow</span>).</p>\n" + render_svg(chart);
  if (!run.map_traces.empty() && run.map_traces.size() == run.map.size() && points.size() == run.map.size()) html += trace_view(run);
  if (!run.map_lidars.empty() && run.map_lidars.size() == run.map.size() && points.size() == run.map.size()) html += lidar_view(run);
  return Section{"map", "Map", html};
}

}  // namespace mlidar::report
