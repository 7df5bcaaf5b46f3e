// The trajectory section of report.html: top and side views with equal axes,
// the ground truth and the error over time when the dataset has them, and the
// poses' 1-sigma over time from pose_covariance.txt (with the NEES against the
// ground truth when there is one).
#include <cmath>
#include <sstream>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/covariance.hpp"
#include "mlidar/eval/pose_nees.hpp"
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

/// "SE(3)-aligned" and the like.
std::string aligned_words(eval::AlignMode mode) {
  switch (mode) {
    case eval::AlignMode::kNone:
      return "not aligned";
    case eval::AlignMode::kOrigin:
      return "first poses aligned";
    case eval::AlignMode::kSe3:
      return "SE(3)-aligned";
    case eval::AlignMode::kSim3:
      return "Sim(3)-aligned";
  }
  return "aligned";
}

/// The estimate's legend: "estimate (aligned, SE(3))" and the like.
std::string alignment_words(eval::AlignMode mode) {
  switch (mode) {
    case eval::AlignMode::kSe3:
      return "estimate (aligned, SE(3))";
    case eval::AlignMode::kSim3:
      return "estimate (aligned, Sim(3))";
    default:
      return "estimate (" + aligned_words(mode) + ")";
  }
}

Chart view(const std::string& title, int horizontal, int vertical, const std::vector<SE3>& estimate, const std::vector<SE3>* truth,
           eval::AlignMode align) {
  Chart chart = spatial_view(title, horizontal, vertical);
  if (truth != nullptr) chart.series.push_back({"ground truth", kTruthColour, positions(*truth, horizontal), positions(*truth, vertical)});
  chart.series.push_back({truth != nullptr ? alignment_words(align) : "estimate", kEstimateColour, positions(estimate, horizontal),
                          positions(estimate, vertical)});
  return chart;
}

/// The translation 1-sigma per axis over time (log scale: it grows by decades along a run).
Chart uncertainty_chart(const std::vector<io::StampedCovariance>& covariances) {
  Chart chart;
  chart.title = "Pose uncertainty (1 sigma per axis)";
  chart.x_label = "time (s)";
  chart.y_label = "sigma (m)";
  chart.log_y = true;
  static const char* const kAxes[] = {"x", "y", "z"};
  static const char* const kColours[] = {"#d62728", "#2ca02c", "#1f77b4"};
  for (int axis = 0; axis < 3; ++axis) {
    Series series{std::string("sigma ") + kAxes[axis], kColours[axis], {}, {}};
    for (const io::StampedCovariance& c : covariances) {
      series.x.push_back(c.stamp - covariances.front().stamp);
      series.y.push_back(axis_sigmas(c.covariance)(axis));
    }
    chart.series.push_back(std::move(series));
  }
  return chart;
}

/// The last pose's 1-sigma in words and, with a ground truth, how often the error lies inside its 95 % band.
std::string uncertainty_words(const RunData& run, const std::optional<eval::TrajectoryReport>& evaluated) {
  const Vec6 sigma = axis_sigmas(run.pose_covariances.back().covariance);
  std::ostringstream html;
  html << "<p>Pose 1&sigma; at the last frame: x " << fixed(sigma(0), 3) << " m, y " << fixed(sigma(1), 3) << " m, z " << fixed(sigma(2), 3)
       << " m; rotation " << fixed(rad_to_deg(sigma.tail<3>().maxCoeff()), 2)
       << "&deg; (largest axis). It grows from zero at the first frame (pose_covariance.txt).";
  if (evaluated) {
    try {
      std::vector<double> stamps;
      for (const StampedPose& p : run.trajectory->poses) stamps.push_back(p.stamp);
      const eval::PoseNees nees = eval::evaluate_pose_nees(*evaluated, run.pose_covariances, "pose_covariance.txt", stamps);
      html << " Against the ground truth (aligned at the first pose): " << fixed(100 * nees.pose.inside, 0)
           << " % of the frames inside the 95 % NEES band (" << fixed(100 * nees.pose.below, 0)
           << " % below: the covariance is larger than the error; " << fixed(100 * nees.pose.above, 0) << " % above: smaller).";
    } catch (const std::exception& error) {
      html << " Not compared with the ground truth: " << escape_markup(error.what());
    }
  }
  html << "</p>\n";
  return html.str();
}

/// SE(3) alignment, or the one an `eval traj` run used (its eval.json).
eval::TrajectoryEvalOptions evaluation_options(const RunData& run) {
  eval::TrajectoryEvalOptions options;
  if (run.command != "eval traj" || !run.metrics.is_object() || !run.metrics.contains("alignment")) return options;
  const std::string mode = run.metrics["alignment"].value("mode", std::string{});
  for (const eval::AlignMode m : {eval::AlignMode::kNone, eval::AlignMode::kOrigin, eval::AlignMode::kSe3, eval::AlignMode::kSim3})
    if (mode == eval::align_mode_name(m)) options.align = m;
  return options;
}

}  // namespace

Chart spatial_view(const std::string& title, int horizontal, int vertical) {
  static const char* const kNames[] = {"x (m)", "y (m)", "z (m)"};
  Chart chart;
  chart.title = title;
  chart.x_label = kNames[horizontal];
  chart.y_label = kNames[vertical];
  chart.equal_axes = true;
  chart.width = 640;
  chart.height = 480;
  return chart;
}

std::optional<Section> trajectory_section(const RunData& run) {
  if (!run.trajectory || run.trajectory->empty()) return std::nullopt;
  std::vector<SE3> estimate;
  for (const StampedPose& p : run.trajectory->poses) estimate.push_back(p.T_world_base);
  std::ostringstream html;
  std::optional<eval::TrajectoryReport> evaluated;
  const eval::TrajectoryEvalOptions options = evaluation_options(run);
  if (run.gt_trajectory) {
    try {
      evaluated = eval::evaluate_trajectory(*run.gt_trajectory, *run.trajectory, options, "groundtruth/trajectory.tum", "trajectory.tum");
    } catch (const std::exception& error) {
      html << "<p class=\"note\">Not compared with the ground truth: " << escape_markup(error.what()) << "</p>\n";
    }
  }
  const std::vector<SE3>& shown = evaluated ? evaluated->est_aligned : estimate;
  const std::vector<SE3>* truth = evaluated ? &evaluated->gt : nullptr;
  if (evaluated)
    html << "<p>ATE (" << aligned_words(options.align) << ") RMSE " << fixed(evaluated->ate.translation_m.rmse, 4) << " m, max "
         << fixed(evaluated->ate.translation_m.max, 4) << " m; rotation RMSE " << fixed(evaluated->ate.rotation_deg.rmse, 3)
         << "&deg; over " << evaluated->gt.size() << " poses.</p>\n";
  html << "<div class=\"figures\">\n"
       << render_svg(view("Top view", 0, 1, shown, truth, options.align))
       << render_svg(view("Side view", 0, 2, shown, truth, options.align));
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
  if (!run.pose_covariances.empty()) html << render_svg(uncertainty_chart(run.pose_covariances));
  html << "</div>\n";
  if (!run.pose_covariances.empty()) html << uncertainty_words(run, evaluated);
  return Section{"trajectory", "Trajectory", html.str()};
}

}  // namespace mlidar::report
