// The stages of `calibrate auto` in report.html (calibration.json): hand-eye's
// estimate (thesis Chap. 3 motion stage), the start of the appearance
// refinement and its result, each against ground truth when there is one.
#include "mlidar/core/conversions.hpp"
#include "mlidar/eval/calibration_metrics.hpp"
#include "mlidar/report/report_sections.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {
namespace {

std::vector<std::string> pose_cells(const std::optional<SE3>& T, const io::LidarExtrinsic* truth) {
  if (!T) return {"-", "-", "-"};
  const Vec3 t = T->translation();
  const Vec3 rpy = rpy_deg_from_quat(T->rotation());
  std::string error = "-";
  if (truth != nullptr) {
    const eval::ExtrinsicError e = eval::extrinsic_error(truth->T_base_lidar, *T, std::nullopt);
    error = fixed(e.rotation_error_deg, 3) + " / " + fixed(100.0 * e.translation_error_m, 2);
  }
  return {fixed(t.x(), 4) + ", " + fixed(t.y(), 4) + ", " + fixed(t.z(), 4),
          fixed(rpy.x(), 3) + ", " + fixed(rpy.y(), 3) + ", " + fixed(rpy.z(), 3), error};
}

std::string text_of(const nlohmann::json& object, const char* key) {
  return object.is_object() && object.contains(key) && object[key].is_string() ? escape_markup(object[key].get<std::string>()) : "";
}

}  // namespace

std::optional<Section> autocalib_stages_section(const RunData& run) {
  if (run.command != "calibrate auto" || !run.metrics.contains("lidars") || !run.metrics["lidars"].is_array()) return std::nullopt;
  const std::string base = run.metrics.value("base", std::string{});
  std::vector<std::vector<std::string>> rows;
  for (const auto& lidar : run.metrics["lidars"]) {
    const std::string name = lidar.value("name", std::string("?"));
    if (name == base) continue;
    const io::LidarExtrinsic* truth = run.gt_extrinsics ? run.gt_extrinsics->find(name) : nullptr;
    const nlohmann::json handeye = lidar.value("handeye", nlohmann::json::object());
    const nlohmann::json refine = lidar.value("refine", nlohmann::json::object());
    const auto row = [&](const std::string& stage, const std::optional<SE3>& T, const std::string& note) {
      std::vector<std::string> cells{escape_markup(name), stage};
      for (std::string& c : pose_cells(T, truth)) cells.push_back(std::move(c));
      cells.push_back(note);
      rows.push_back(std::move(cells));
    };
    row("hand-eye", pose_of(handeye.value("T_base_lidar", nlohmann::json())), text_of(handeye, "message"));
    if (refine.is_object() && !refine.empty()) {
      row("refinement start (" + text_of(refine, "start") + ")", pose_of(refine.value("start_estimate", nlohmann::json())), "");
      row("refined", pose_of(refine.value("estimate", nlohmann::json())),
          text_of(refine, "verdict") + " " + std::to_string(refine.value("candidates_kept", 0)) + "/" +
              std::to_string(refine.value("candidates_tried", 0)) + " candidates " + text_of(refine, "message"));
    }
    row("<b>result</b>", pose_of(lidar.value("T_base_lidar", nlohmann::json())),
        text_of(lidar, "verdict") + " " + text_of(lidar, "reason"));
  }
  if (rows.empty()) return std::nullopt;
  return Section{"stages", "Calibration stages",
                 "<p>T_base_lidar after each stage of calibration.json; the error is against the dataset's ground truth.</p>\n" +
                     html_table({"LiDAR", "stage", "translation (m)", "roll, pitch, yaw (deg)", "error (deg / cm)", "verdict"}, rows)};
}

}  // namespace mlidar::report
