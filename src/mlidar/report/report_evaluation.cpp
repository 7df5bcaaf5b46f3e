// The evaluation section of an `eval traj --out` run's report.html, from its
// eval.json (src/mlidar/eval/report.hpp): the error statistics, the KITTI
// drift per segment length (the devkit's error-against-path-length plots)
// and, with --covariance, the poses' NEES over time against its 95 % band.
#include <sstream>

#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

std::vector<std::string> stats_row(const std::string& name, const nlohmann::json& stats, int digits) {
  std::vector<std::string> row{name};
  for (const char* key : {"rmse", "mean", "median", "max"}) row.push_back(fixed(number_of(stats.value(key, nlohmann::json())), digits));
  row.push_back(stats.is_object() && stats.contains("count") ? stats["count"].dump() : "-");
  return row;
}

std::string statistics_table(const nlohmann::json& metrics) {
  const nlohmann::json ate = metrics.value("ate", nlohmann::json::object());
  const nlohmann::json rpe = metrics.value("rpe", nlohmann::json::object());
  const std::string step =
      rpe.contains("delta") ? short_number(number_of(rpe["delta"])) + " " + rpe.value("delta_unit", std::string{}) : "-";
  std::vector<std::vector<std::string>> rows{
      stats_row("ATE translation (m)", ate.value("translation_m", nlohmann::json()), 4),
      stats_row("ATE rotation (deg)", ate.value("rotation_deg", nlohmann::json()), 3),
      stats_row("RPE translation (m), step " + escape_markup(step), rpe.value("translation_m", nlohmann::json()), 4),
      stats_row("RPE translation (% of path)", rpe.value("translation_percent", nlohmann::json()), 3),
      stats_row("RPE rotation (deg)", rpe.value("rotation_deg", nlohmann::json()), 3)};
  return html_table({"error", "RMSE", "mean", "median", "max", "pairs"}, rows);
}

Chart drift_chart(const nlohmann::json& by_length, const char* key, std::string title, std::string y_label, const char* colour) {
  Chart chart;
  chart.title = std::move(title);
  chart.x_label = "segment length (m)";
  chart.y_label = std::move(y_label);
  Series line{"mean over the segments of this length", colour, {}, {}};
  for (const auto& drift : by_length) {
    line.x.push_back(number_of(drift.value("length_m", nlohmann::json())));
    line.y.push_back(number_of(drift.value(key, nlohmann::json())));
  }
  Series dots = line;
  dots.label.clear();
  dots.dots = true;
  chart.series.push_back(std::move(line));
  chart.series.push_back(std::move(dots));
  chart.lines.push_back({0.0, "", "#999"});
  return chart;
}

std::string kitti_html(const nlohmann::json& kitti) {
  if (!kitti.is_object())
    return "<p>No KITTI drift: the ground-truth path is shorter than the shortest KITTI segment (100 m; the devkit uses "
           "100-800 m).</p>\n";
  std::ostringstream html;
  html << "<p>KITTI odometry metric (devkit evaluate_odometry: segments of 100-800 m of ground-truth path from every 10th "
          "frame): <b>"
       << fixed(number_of(kitti["translation_percent"]), 3) << " %</b> translation, <b>"
       << fixed(number_of(kitti["rotation_deg_per_100m"]), 4) << " deg/100 m</b> rotation over " << kitti.value("segments", 0)
       << " segments.</p>\n";
  const nlohmann::json by_length = kitti.value("by_length", nlohmann::json::array());
  if (by_length.empty()) return html.str();
  std::vector<std::vector<std::string>> rows;
  for (const auto& drift : by_length)
    rows.push_back({fixed(number_of(drift["length_m"]), 0), drift.value("segments", nlohmann::json()).dump(),
                    fixed(number_of(drift["translation_percent"]), 3), fixed(number_of(drift["rotation_deg_per_100m"]), 4)});
  html << "<div class=\"figures\">\n"
       << render_svg(drift_chart(by_length, "translation_percent", "KITTI translation drift per segment length", "drift (%)", "#d62728"))
       << render_svg(
              drift_chart(by_length, "rotation_deg_per_100m", "KITTI rotation drift per segment length", "drift (deg / 100 m)", "#1f77b4"))
       << "</div>\n"
       << html_table({"length (m)", "segments", "translation (%)", "rotation (deg/100 m)"}, rows);
  return html.str();
}

std::string nees_html(const nlohmann::json& nees) {
  const nlohmann::json pose = nees.value("pose", nlohmann::json::object());
  const nlohmann::json band = pose.value("band_95", nlohmann::json::array());
  Chart chart;
  chart.title = "Pose NEES over time (6 dof) and its 95 % band";
  chart.x_label = "time (s)";
  chart.y_label = "NEES";
  chart.log_y = true;
  Series values{"NEES", "#9467bd", {}, {}};
  values.dots = true;
  const nlohmann::json stamps = nees.value("stamps", nlohmann::json::array());
  const nlohmann::json nees_values = nees.value("values", nlohmann::json::array());
  for (std::size_t i = 0; i < std::min(stamps.size(), nees_values.size()); ++i) {
    values.x.push_back(number_of(stamps[i]) - number_of(stamps[0]));
    values.y.push_back(number_of(nees_values[i]));
  }
  chart.series.push_back(std::move(values));
  if (band.size() == 2) {
    chart.lines.push_back({number_of(band[0]), "95 % low", "#555"});
    chart.lines.push_back({number_of(band[1]), "95 % high", "#555"});
  }
  std::ostringstream html;
  html << "<p>The estimate's pose covariances (--covariance) against its errors, aligned at the first pose: "
       << fixed(100.0 * number_of(pose.value("inside", nlohmann::json())), 0) << " % of " << pose.value("frames", nlohmann::json()).dump()
       << " poses inside the 95 % band (" << fixed(100.0 * number_of(pose.value("below", nlohmann::json())), 0)
       << " % below: the covariance is larger than the error; " << fixed(100.0 * number_of(pose.value("above", nlohmann::json())), 0)
       << " % above: smaller).</p>\n"
       << render_svg(chart);
  return html.str();
}

}  // namespace

std::optional<Section> evaluation_section(const RunData& run) {
  if (run.command != "eval traj" || !run.metrics.is_object()) return std::nullopt;
  const nlohmann::json& metrics = run.metrics;
  const nlohmann::json alignment = metrics.value("alignment", nlohmann::json::object());
  std::ostringstream html;
  html << "<p>" << metrics.value("matched_poses", nlohmann::json()).dump() << " poses associated of "
       << metrics.value("est_poses", nlohmann::json()).dump() << " estimated and " << metrics.value("gt_poses", nlohmann::json()).dump()
       << " ground-truth poses; alignment <b>" << escape_markup(alignment.value("mode", std::string("?"))) << "</b>";
  if (alignment.value("mode", std::string{}) == "sim3")
    html << " (scale " << fixed(number_of(alignment.value("scale", nlohmann::json())), 4) << ")";
  html << ". Definitions of evo (ATE = APE, RPE) and of the KITTI devkit.</p>\n"
       << statistics_table(metrics) << "<h3>Drift per segment length</h3>\n"
       << kitti_html(metrics.value("kitti", nlohmann::json()));
  if (metrics.contains("pose_nees") && metrics["pose_nees"].is_object())
    html << "<h3>Pose covariance</h3>\n" << nees_html(metrics["pose_nees"]);
  return Section{"evaluation", "Evaluation", html.str()};
}

}  // namespace mlidar::report
