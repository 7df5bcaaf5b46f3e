// Per-LiDAR online calibration sections of report.html (slam's per-frame windows):
// lambda_min per window against lambda_calib (Algorithm 1), the window
// estimates minus the final one with +-2 sigma bands from each window's
// information, and how the LiDAR started.
#include <cctype>
#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>

#include "mlidar/core/conversions.hpp"
#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

constexpr const char* kAxisColours[] = {"#d62728", "#2ca02c", "#1f77b4"};
constexpr const char* kAxisNames[] = {"x", "y", "z"};

std::optional<Mat6> matrix_of(const nlohmann::json& json) {
  if (!json.is_array() || json.size() != 36) return std::nullopt;
  Mat6 m;
  for (int i = 0; i < 36; ++i) m(i / 6, i % 6) = number_of(json[static_cast<std::size_t>(i)]);
  if (!m.allFinite()) return std::nullopt;
  return m;
}

/// [t (m), r (rad)] of T relative to `final`: t - t_final and Log(R_final^T R).
Vec6 deviation(const SE3& T, const SE3& final) {
  Vec6 d;
  d.head<3>() = T.translation() - final.translation();
  d.tail<3>() = so3_log(final.rotation().conjugate() * T.rotation());
  return d;
}

/// 1-sigma per axis of a window, sigma^2 Lambda^-1 (its residual variance over its information, as in
/// Xi_calib's `windows` term); NaN when the information is not invertible or the variance unknown.
Vec6 sigmas(const std::optional<Mat6>& information, double residual_variance) {
  Vec6 out = Vec6::Constant(std::nan(""));
  if (!information || !(residual_variance > 0.0)) return out;
  const Eigen::LDLT<Mat6> ldlt(*information);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return out;
  const Mat6 covariance = residual_variance * ldlt.solve(Mat6::Identity());
  for (int i = 0; i < 6; ++i) out(i) = covariance(i, i) > 0.0 ? std::sqrt(covariance(i, i)) : std::nan("");
  return out;
}

struct WindowSeries {
  std::vector<double> time;
  std::vector<Vec6> value, sigma;
  std::vector<double> lambda_time, lambda, lambda_accepted_time, lambda_accepted;
};

WindowSeries windows_of(const RunData& run, const std::string& name, const SE3& final) {
  WindowSeries w;
  const nlohmann::json& frames = run.metrics["per_frame"];
  const double first = frames.empty() ? 0.0 : number_of(frames.front().value("stamp", nlohmann::json()));
  for (const auto& frame : frames) {
    if (!frame.contains("lidars") || !frame["lidars"].contains(name)) continue;
    const nlohmann::json& l = frame["lidars"][name];
    const double t = number_of(frame.value("stamp", nlohmann::json())) - first;
    const double lambda = number_of(l.value("lambda_min", nlohmann::json()));
    if (std::isfinite(lambda)) {
      const bool accepted = l.value("accepted", false);
      (accepted ? w.lambda_accepted_time : w.lambda_time).push_back(t);
      (accepted ? w.lambda_accepted : w.lambda).push_back(lambda);
    }
    if (const auto estimate = pose_of(l.value("window_estimate", nlohmann::json()))) {
      w.time.push_back(t);
      w.value.push_back(deviation(*estimate, final));
      w.sigma.push_back(sigmas(matrix_of(l.value("window_information", nlohmann::json())),
                               number_of(l.value("window_residual_variance_m2", nlohmann::json()))));
    }
  }
  return w;
}

/// Axes [first, first + 3) of the windows, scaled (100: m to cm; 180/pi: rad to deg), with +-2 sigma bands.
Chart estimates_chart(const std::string& title, const std::string& unit, const WindowSeries& w, int first, double scale,
                      const std::optional<Vec6>& truth) {
  Chart chart;
  chart.title = title;
  chart.x_label = "time (s)";
  chart.y_label = "window - final (" + unit + ")";
  chart.width = 640;
  chart.height = 320;
  for (int a = 0; a < 3; ++a) {
    Series s{kAxisNames[a], kAxisColours[a], w.time, {}};
    Band band{kAxisColours[a], {}, {}, {}};
    for (std::size_t i = 0; i < w.time.size(); ++i) {
      const double v = scale * w.value[i](first + a), sd = scale * w.sigma[i](first + a);
      s.y.push_back(v);
      if (!std::isfinite(sd)) continue;
      band.x.push_back(w.time[i]);
      band.lo.push_back(v - 2.0 * sd);
      band.hi.push_back(v + 2.0 * sd);
    }
    chart.series.push_back(std::move(s));
    chart.bands.push_back(std::move(band));
    if (truth) chart.lines.push_back({scale * (*truth)(first + a), std::string("truth ") + kAxisNames[a], kAxisColours[a]});
  }
  return chart;
}

Chart lambda_chart(const RunData& run, const WindowSeries& w) {
  Chart chart;
  chart.title = "lambda_min of each calibration window (Algorithm 1)";
  chart.x_label = "time (s)";
  chart.y_label = "lambda_min";
  chart.log_y = true;
  chart.width = 640;
  chart.height = 320;
  chart.series.push_back({"accepted", "#2a9d3a", w.lambda_accepted_time, w.lambda_accepted, true});
  chart.series.push_back({"not accepted", "#999", w.lambda_time, w.lambda, true});
  const double lambda_calib =
      run.metrics.contains("convergence") ? number_of(run.metrics["convergence"].value("lambda_calib", nlohmann::json())) : std::nan("");
  if (std::isfinite(lambda_calib)) chart.lines.push_back({lambda_calib, "lambda_calib " + short_number(lambda_calib), "#c62828"});
  return chart;
}

std::string start_table(const nlohmann::json& lidar) {
  const nlohmann::json init = lidar.value("initialization", nlohmann::json::object());
  std::vector<std::vector<std::string>> rows;
  const auto text = [](const nlohmann::json& v) { return escape_markup(v.is_string() ? v.get<std::string>() : v.dump()); };
  rows.push_back({"state at the end of initialization", text(init.value("state", nlohmann::json("-")))});
  rows.push_back({"started from", text(init.value("translation_start", nlohmann::json("-"))) + " at frame " +
                                      text(init.value("frame", nlohmann::json("-")))});
  rows.push_back({"first / last convergence (frame)", text(lidar.value("first_converged_frame", nlohmann::json("-"))) + " / " +
                                                          text(lidar.value("converged_frame", nlohmann::json("-")))});
  rows.push_back({"accepted windows, outliers",
                  text(lidar.value("accepted", nlohmann::json(0))) + ", " + text(lidar.value("outlier_windows", nlohmann::json(0)))});
  for (const auto& u : init.value("unobservable_from_motion", nlohmann::json::array()))
    rows.push_back({"not observable from motion", text(u)});
  for (const auto& a : init.value("appearance", nlohmann::json::array()))
    rows.push_back({"appearance attempt at frame " + text(a.value("frame", nlohmann::json("-"))),
                    text(a.value("verdict", nlohmann::json("-"))) + (a.value("searched", false) ? " (searched)" : "") + ", " +
                        fixed(number_of(a.value("seconds", nlohmann::json())), 1) + " s"});
  return html_table({"", ""}, rows);
}

std::string section_id(const std::string& name) {
  std::string id = "calibration-";
  for (const char c : name) id += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return id;
}

}  // namespace

std::optional<SE3> pose_of(const nlohmann::json& json) {
  if (!json.is_object() || !json.contains("translation") || !json.contains("quaternion_wxyz")) return std::nullopt;
  const auto& t = json["translation"];
  const auto& q = json["quaternion_wxyz"];
  if (!t.is_array() || t.size() != 3 || !q.is_array() || q.size() != 4) return std::nullopt;
  const Quat rotation(number_of(q[0]), number_of(q[1]), number_of(q[2]), number_of(q[3]));
  if (!(rotation.norm() > 0.5)) return std::nullopt;  // also NaN
  return SE3(rotation.normalized(), Vec3(number_of(t[0]), number_of(t[1]), number_of(t[2])));
}

std::vector<Section> calibration_sections(const RunData& run) {
  std::vector<Section> out;
  if (!run.metrics.contains("per_lidar") || !run.metrics["per_lidar"].is_object() || !run.metrics.contains("per_frame") ||
      !run.metrics["per_frame"].is_array())
    return out;
  for (const auto& [name, lidar] : run.metrics["per_lidar"].items()) {
    const std::optional<SE3> final = pose_of(lidar);
    if (!final) continue;
    const WindowSeries w = windows_of(run, name, *final);
    if (w.time.empty() && w.lambda.empty() && w.lambda_accepted.empty()) continue;
    std::optional<Vec6> truth;
    if (run.gt_extrinsics)
      if (const io::LidarExtrinsic* t = run.gt_extrinsics->find(name)) truth = deviation(t->T_base_lidar, *final);
    std::ostringstream html;
    html << start_table(lidar) << "<div class=\"figures\">\n"
         << render_svg(lambda_chart(run, w))
         << render_svg(estimates_chart("Translation of each window minus the final, +-2 sigma", "cm", w, 0, 100.0, truth))
         << render_svg(estimates_chart("Rotation of each window minus the final (tangent), +-2 sigma", "deg", w, 3, rad_to_deg(1.0), truth))
         << "</div>\n";
    out.push_back({section_id(name), "Calibration of " + name, html.str()});
  }
  return out;
}

}  // namespace mlidar::report
