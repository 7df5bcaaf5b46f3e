// Summary (facts, verdicts and warnings in words) and the extrinsics table of report.html.
#include <cmath>
#include <sstream>

#include "mlidar/calib/extrinsic_check.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/eval/calibration_metrics.hpp"
#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

struct Verdict {
  std::string level;  ///< "ok", "warn", "bad"
  std::string text;
};

std::string joined(const nlohmann::json& strings, const std::string& separator) {
  std::string out;
  if (!strings.is_array()) return out;
  for (const auto& s : strings) {
    if (!s.is_string() && !s.is_number_integer()) continue;
    if (!out.empty()) out += separator;
    out += s.is_string() ? s.get<std::string>() : std::to_string(s.get<long long>());
  }
  return out;
}

std::string frame_text(const nlohmann::json& frame) { return frame.is_number() ? std::to_string(frame.get<long long>()) : "-"; }

/// A given extrinsic's disagreement as metrics.json records it (slam's per_lidar.NAME.extrinsic_check, odometry's
/// extrinsic_check entries).
calib::DisagreementEvidence evidence_of(const nlohmann::json& check) {
  const nlohmann::json frame = check.value("disagreed_frame", nlohmann::json());
  calib::DisagreementEvidence evidence{.frame = frame.is_number_unsigned() ? frame.get<std::size_t>() : 0,
                                       .residual_ratio = number_of(check.value("residual_ratio", nlohmann::json())),
                                       .map_ratio = number_of(check.value("map_ratio", nlohmann::json())),
                                       .frames_lost = check.value("frames_lost", false)};
  const nlohmann::json compared_with = check.value("compared_with", nlohmann::json());
  if (compared_with.is_string()) evidence.reference = compared_with.get<std::string>();
  return evidence;
}

/// slam: one verdict per LiDAR of metrics.per_lidar, then the frames.
void slam_verdicts(const RunData& run, std::vector<Verdict>& out) {
  const nlohmann::json& metrics = run.metrics;
  const std::string base = run.extrinsics ? run.extrinsics->base : std::string{};
  if (metrics.contains("per_lidar") && metrics["per_lidar"].is_object()) {
    for (const auto& [name, lidar] : metrics["per_lidar"].items()) {
      if (name == base) continue;
      const nlohmann::json check = lidar.value("extrinsic_check", nlohmann::json());
      if (check.is_object())
        out.push_back({"bad", name + ": the given extrinsic disagrees with the map (" + calib::describe(evidence_of(check)) + "); " +
                                  (check.value("recalibrated", false) ? "calibrated online from it: see extrinsics.yaml and fix the input"
                                                                      : "used as given: the trajectory and map may be wrong")});
      const nlohmann::json converged = lidar.value("converged_frame", nlohmann::json());
      if (metrics.value("calibrate", std::string{}) != "online") continue;
      if (converged.is_number()) {
        const nlohmann::json init = lidar.value("initialization", nlohmann::json::object());
        out.push_back({"ok", name + ": calibrated online, converged at frame " +
                                 frame_text(lidar.value("first_converged_frame", converged)) + " (started from " +
                                 init.value("translation_start", std::string("motion")) + " at frame " +
                                 frame_text(init.value("frame", nlohmann::json())) + ")"});
      } else {
        const nlohmann::json init = lidar.value("initialization", nlohmann::json::object());
        const std::string why = joined(init.value("unobservable_from_motion", nlohmann::json::array()), "; ");
        out.push_back({"bad", name + ": not calibrated (" + lidar.value("role", std::string("?")) + ", " +
                                  init.value("state", std::string("?")) + ")" + (why.empty() ? std::string{} : ": " + why) +
                                  ". Its extrinsic in extrinsics.yaml is the input's, without a covariance; try more turning, "
                                  "`--calibrate refine` or `mlidar calibrate auto`."});
      }
    }
  }
}

/// slam and odometry: lost, suspect and degenerate frames and gaps in the input.
void frame_verdicts(const nlohmann::json& metrics, std::vector<Verdict>& out) {
  const auto count = [&](const char* key) {
    return metrics.contains(key) && metrics[key].is_number() ? metrics[key].get<long long>() : 0LL;
  };
  if (count("lost_frames") > 0)
    out.push_back({"bad", std::to_string(count("lost_frames")) + " frame(s) could not be registered (lost): their poses are predictions"});
  if (metrics.contains("map_restarts") && metrics["map_restarts"].is_array() && !metrics["map_restarts"].empty())
    out.push_back({"bad", "the local map was started again at frame(s) " + joined(metrics["map_restarts"], ", ") +
                              " after registrations failed in a row: each part of the trajectory is measured, but the offset "
                              "between them is the motion prediction's"});
  if (metrics.contains("extrinsic_check") && metrics["extrinsic_check"].is_array())  // odometry's (slam's: per LiDAR)
    for (const auto& d : metrics["extrinsic_check"])
      out.push_back({"bad", d.value("lidar", std::string("?")) + ": the given extrinsic disagrees with the map (" +
                                calib::describe(evidence_of(d)) +
                                "): the trajectory and map may be wrong; calibrate it with `mlidar slam --calibrate refine`"});
  if (count("suspect_frames") > 0)
    out.push_back({"warn", std::to_string(count("suspect_frames")) + " frame(s) suspect: registered but not trusted, left out of the map"});
  if (metrics.contains("skipped_scans") && metrics["skipped_scans"].is_array() && !metrics["skipped_scans"].empty())
    out.push_back({"warn", std::to_string(metrics["skipped_scans"].size()) + " scan gap(s) in the input (metrics.json skipped_scans)"});
  if (count("degenerate_frames") > 0)
    out.push_back({"warn", std::to_string(count("degenerate_frames")) +
                               " frame(s) degenerate: the translation along a weak direction (e.g. a corridor's axis) is the motion "
                               "prediction's, not measured"});
}

/// calibrate auto: calibration.json lidars [{name, verdict, reason, advice}].
void calibration_verdicts(const RunData& run, std::vector<Verdict>& out) {
  if (!run.metrics.contains("lidars") || !run.metrics["lidars"].is_array()) return;
  const std::string base = run.metrics.value("base", std::string{});
  for (const auto& lidar : run.metrics["lidars"]) {
    const std::string name = lidar.value("name", std::string("?"));
    if (name == base) continue;
    const std::string verdict = lidar.value("verdict", std::string("?"));
    if (verdict == "ok") {
      out.push_back({"ok", name + ": calibrated (" + verdict + ")"});
    } else {
      std::string text = name + ": " + verdict;
      if (!lidar.value("reason", std::string{}).empty()) text += " - " + lidar.value("reason", std::string{});
      if (!lidar.value("advice", std::string{}).empty()) text += ". " + lidar.value("advice", std::string{});
      out.push_back({"bad", text});
    }
  }
}

/// eval traj: the error in one line, then what was not evaluated and what the covariance says.
void evaluation_verdicts(const RunData& run, std::vector<Verdict>& out) {
  const nlohmann::json& m = run.metrics;
  if (!m.is_object()) return;
  const double matched = number_of(m.value("matched_poses", nlohmann::json())), est = number_of(m.value("est_poses", nlohmann::json()));
  const nlohmann::json ate = m.value("ate", nlohmann::json::object()).value("translation_m", nlohmann::json::object());
  std::string text = "ATE RMSE " + fixed(number_of(ate.value("rmse", nlohmann::json())), 4) + " m (max " +
                     fixed(number_of(ate.value("max", nlohmann::json())), 4) + " m) over " + fixed(matched, 0) + " poses";
  const nlohmann::json kitti = m.value("kitti", nlohmann::json());
  if (kitti.is_object())
    text += "; KITTI drift " + fixed(number_of(kitti["translation_percent"]), 3) + " %, " +
            fixed(number_of(kitti["rotation_deg_per_100m"]), 4) + " deg/100 m";
  out.push_back({"ok", text});
  if (matched < est)
    out.push_back({"warn", fixed(est - matched, 0) + " of " + fixed(est, 0) +
                               " estimated poses have no ground-truth pose within --max-dt and are not evaluated"});
  if (!kitti.is_object()) out.push_back({"warn", "ground-truth path shorter than 100 m: no KITTI drift"});
  if (m.contains("pose_nees") && m["pose_nees"].is_object()) {
    const nlohmann::json pose = m["pose_nees"].value("pose", nlohmann::json::object());
    const double inside = number_of(pose.value("inside", nlohmann::json())), above = number_of(pose.value("above", nlohmann::json()));
    if (inside < 0.9)
      out.push_back({"warn", "the pose covariance is not consistent with the error: " + fixed(100 * inside, 0) + " % of the poses inside " +
                                 "the 95 % NEES band (" + fixed(100 * above, 0) + " % above it: covariance too small)"});
  }
}

std::string facts(const RunData& run) {
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"command", escape_markup(run.command)});
  if (!run.dataset.empty()) rows.push_back({"dataset", escape_markup(run.dataset)});
  if (run.run_info.is_object()) {
    rows.push_back({"started (UTC)", escape_markup(run.run_info.value("started_utc", std::string("-")))});
    rows.push_back({"finished (UTC)", escape_markup(run.run_info.value("finished_utc", std::string("-")))});
    rows.push_back({"mlidar", escape_markup(run.run_info.value("version", std::string("-")))});
    if (run.run_info.contains("arguments") && run.run_info["arguments"].is_array())
      rows.push_back({"command line", "<code>" + escape_markup(joined(run.run_info["arguments"], " ")) + "</code>"});
  }
  if (run.metrics.contains("frames")) rows.push_back({"frames", escape_markup(run.metrics["frames"].dump())});
  if (run.metrics.contains("calibrate")) rows.push_back({"extrinsics", escape_markup(run.metrics.value("calibrate", std::string{}))});
  if (run.trajectory && run.trajectory->size() >= 2)
    rows.push_back({"duration", fixed(run.trajectory->poses.back().stamp - run.trajectory->poses.front().stamp, 1) + " s"});
  return html_table({"", ""}, rows);
}

/// 1-sigma of the translation (cm) and rotation (deg) axes of a [t, r] covariance, as text.
std::string sigma_text(const std::optional<Mat6>& covariance, int first) {
  if (!covariance) return "-";
  std::string out;
  for (int i = first; i < first + 3; ++i) {
    const double sd = std::sqrt(std::max(0.0, (*covariance)(i, i)));
    out += (out.empty() ? "" : " / ") + (first == 0 ? fixed(100.0 * sd, 2) : fixed(rad_to_deg(sd), 3));
  }
  return out;
}

}  // namespace

Section summary_section(const RunData& run) {
  std::vector<Verdict> verdicts;
  if (run.command == "slam") slam_verdicts(run, verdicts);
  if (run.command == "slam" || run.command == "odometry") frame_verdicts(run.metrics, verdicts);
  if (run.command == "calibrate auto") calibration_verdicts(run, verdicts);
  if (run.command == "eval traj") evaluation_verdicts(run, verdicts);
  if (verdicts.empty()) verdicts.push_back({"ok", "nothing flagged"});
  std::ostringstream html;
  html << "<ul class=\"verdicts\">\n";
  for (const Verdict& v : verdicts) html << "<li class=\"" << v.level << "\">" << escape_markup(v.text) << "</li>\n";
  html << "</ul>\n" << facts(run);
  for (const std::string& note : run.notes) html << "<p class=\"note\">" << escape_markup(note) << "</p>\n";
  return {"summary", "Summary", html.str()};
}

std::optional<Section> extrinsics_section(const RunData& run) {
  if (!run.extrinsics || run.extrinsics->lidars.empty()) return std::nullopt;
  std::vector<std::vector<std::string>> rows;
  for (const io::LidarExtrinsic& l : run.extrinsics->lidars) {
    const Vec3 t = l.T_base_lidar.translation();
    const Vec3 rpy = rpy_deg_from_quat(l.T_base_lidar.rotation());
    std::vector<std::string> row{escape_markup(l.name), fixed(t.x(), 4) + ", " + fixed(t.y(), 4) + ", " + fixed(t.z(), 4),
                                 fixed(rpy.x(), 3) + ", " + fixed(rpy.y(), 3) + ", " + fixed(rpy.z(), 3), sigma_text(l.covariance, 0),
                                 sigma_text(l.covariance, 3)};
    const io::LidarExtrinsic* truth = run.gt_extrinsics ? run.gt_extrinsics->find(l.name) : nullptr;
    if (truth != nullptr) {
      const eval::ExtrinsicError e = eval::extrinsic_error(truth->T_base_lidar, l.T_base_lidar, l.covariance);
      row.push_back(fixed(e.rotation_error_deg, 3) + " / " + fixed(100.0 * e.translation_error_m, 2));
      row.push_back(e.nees ? fixed(*e.nees, 2) + (e.nees_within_95() ? "" : " (above the 95 % bound 12.59)") : "-");
    }
    rows.push_back(std::move(row));
  }
  std::vector<std::string> header{"LiDAR", "translation (m)", "roll, pitch, yaw (deg)", "1&sigma; x / y / z (cm)",
                                  "1&sigma; rotation (deg)"};
  if (run.gt_extrinsics) {
    header.push_back("error vs ground truth (deg / cm)");
    header.push_back("NEES (6 dof)");
  }
  std::string html = "<p>extrinsics.yaml, T_base_lidar (p_base = R p_lidar + t) with base <b>" + escape_markup(run.extrinsics->base) +
                     "</b>; &sigma; from its covariance ([t, r], rotation in the local tangent); &quot;-&quot;: no covariance "
                     "(not calibrated, or given as input).</p>\n" +
                     html_table(header, rows);
  if (run.metrics.contains("per_lidar") && run.metrics["per_lidar"].is_object()) {
    std::vector<std::vector<std::string>> weak;
    for (const auto& [name, lidar] : run.metrics["per_lidar"].items())
      for (const auto& w : lidar.value("weak_directions", nlohmann::json::array()))
        weak.push_back(
            {escape_markup(name), escape_markup(w.value("description", std::string{})), short_number(number_of(w["eigenvalue"]))});
    if (!weak.empty())
      html += "<p>Weak directions (least information in the calibration windows):</p>\n" +
              html_table({"LiDAR", "direction", "eigenvalue"}, weak);
  }
  return Section{"extrinsics", "Extrinsics", html};
}

}  // namespace mlidar::report
