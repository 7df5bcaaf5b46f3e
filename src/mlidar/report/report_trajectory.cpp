// The trajectory section of report.html: top and side views with equal axes,
// the ground truth and the error over time when the dataset has them.
#include <sstream>

#include "mlidar/eval/trajectory_metrics.hpp"
#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

constexpr const char* kEstimateColour = "#d62728";
constexpr const char* kTruthColour = "#1f77b4";

/// Axis `axis` (0 x, 1 y, 2 z) of each pose's position.
std::vector<double> positions(const std::vector<SE3>& poses, int axis) {
  std::vector<double> out;
  out.reserve(poses.size());
  for (const SE3& T : poses) out.push_back(T.translation()(axis));
  return out;
}

Chart view(const std::string& title, int horizontal, int vertical, const std::vector<SE3>& estimate, const std::vector<SE3>* truth) {
  static const char* const kNames[] = {"x (m)", "y (m)", "z (m)"};
  Chart chart;
  chart.title = title;
  chart.x_label = kNames[horizontal];
  chart.y_label = kNames[vertical];
  chart.equal_axes = true;
  chart.width = 640;
  chart.height = 480;
  if (truth != nullptr) chart.series.push_back({"ground truth", kTruthColour, positions(*truth, horizontal), positions(*truth, vertical)});
  chart.series.push_back({truth != nullptr ? "estimate (aligned, SE(3))" : "estimate", kEstimateColour, positions(estimate, horizontal),
                          positions(estimate, vertical)});
  return chart;
}

}  // namespace

std::optional<Section> trajectory_section(const RunData& run) {
  if (!run.trajectory || run.trajectory->empty()) return std::nullopt;
  std::vector<SE3> estimate;
  for (const StampedPose& p : run.trajectory->poses) estimate.push_back(p.T_world_base);
  std::ostringstream html;
  std::optional<eval::TrajectoryReport> evaluated;
  if (run.gt_trajectory) {
    try {
      evaluated = eval::evaluate_trajectory(*run.gt_trajectory, *run.trajectory, eval::TrajectoryEvalOptions{},
                                            "groundtruth/trajectory.tum", "trajectory.tum");
    } catch (const std::exception& error) {
      html << "<p class=\"note\">Not compared with the ground truth: " << escape_markup(error.what()) << "</p>\n";
    }
  }
  const std::vector<SE3>& shown = evaluated ? evaluated->est_aligned : estimate;
  const std::vector<SE3>* truth = evaluated ? &evaluated->gt : nullptr;
  if (evaluated)
    html << "<p>ATE (SE(3)-aligned) RMSE " << fixed(evaluated->ate.translation_m.rmse, 4) << " m, max "
         << fixed(evaluated->ate.translation_m.max, 4) << " m; rotation RMSE " << fixed(evaluated->ate.rotation_deg.rmse, 3)
         << "&deg; over " << evaluated->gt.size() << " poses.</p>\n";
  html << "<div class=\"figures\">\n"
       << render_svg(view("Top view", 0, 1, shown, truth)) << render_svg(view("Side view", 0, 2, shown, truth));
  if (evaluated && !evaluated->stamps.empty()) {
    Chart error;
    error.title = "Translation error over time (ATE)";
    error.x_label = "time (s)";
    error.y_label = "error (m)";
    std::vector<double> times;
    for (const double t : evaluated->stamps) times.push_back(t - evaluated->stamps.front());
    error.series.push_back({"|t_gt - t_est|", "#2ca02c", times, evaluated->ate.translation_errors_m});
    error.lines.push_back({0.0, "", "#999"});
    html << render_svg(error);
  }
  html << "</div>\n";
  return Section{"trajectory", "Trajectory", html.str()};
}

}  // namespace mlidar::report
