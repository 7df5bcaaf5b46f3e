// Renderings of the detection evaluation (keys in detection_report.hpp).
#include "mlidar/eval/detection_report.hpp"

#include <cmath>
#include <cstdio>

namespace mlidar::eval {
namespace {

/// A fraction as percent, null when not finite.
nlohmann::json percent_or_null(double fraction) { return std::isfinite(fraction) ? nlohmann::json(100.0 * fraction) : nlohmann::json(); }

nlohmann::json ap_json(const ApResult& ap) {
  return {{"ap_r40", percent_or_null(ap.ap_r40)},
          {"ap_r11", percent_or_null(ap.ap_r11)},
          {"true_positives", ap.true_positives},
          {"false_positives", ap.false_positives},
          {"precision_r40", interpolated_precision(ap.curve, RecallPoints::kR40)}};
}

nlohmann::json level_json(const ThresholdResult& level) {
  nlohmann::json json = {{"iou", level.iou}};
  for (const DifficultyResult& d : level.difficulties) {
    json[difficulty_name(d.difficulty)] = {{"ground_truths", d.ground_truths}, {"3d", ap_json(d.box_3d)}, {"bev", ap_json(d.bev)}};
  }
  return json;
}

nlohmann::json mean_json(const MeanAp& mean) {
  return {{"classes", mean.classes},
          {"3d", {{"ap_r40", percent_or_null(mean.ap3d_r40)}, {"ap_r11", percent_or_null(mean.ap3d_r11)}}},
          {"bev", {{"ap_r40", percent_or_null(mean.apbev_r40)}, {"ap_r11", percent_or_null(mean.apbev_r11)}}}};
}

/// "  85.31" or "      -" for NaN, 7 wide.
std::string percent_cell(double fraction) {
  char cell[16];
  if (std::isfinite(fraction)) {
    std::snprintf(cell, sizeof(cell), " %6.2f", 100.0 * fraction);
  } else {
    std::snprintf(cell, sizeof(cell), " %6s", "-");
  }
  return cell;
}

std::string class_row(const ClassResult& c, Difficulty d) {
  const auto index = static_cast<int>(d);
  char head[64];
  std::snprintf(head, sizeof(head), "%-10s %-8s %5d", io::object_class_name(c.object_class).c_str(), difficulty_name(d).c_str(),
                c.levels[0].difficulties[index].ground_truths);
  std::string row = head;
  for (const ThresholdResult& level : c.levels) {
    const DifficultyResult& r = level.difficulties[index];
    char iou[16];
    std::snprintf(iou, sizeof(iou), " | %4.2f", level.iou);
    row += iou + percent_cell(r.box_3d.ap_r40) + percent_cell(r.box_3d.ap_r11) + percent_cell(r.bev.ap_r40);
  }
  return row + '\n';
}

std::string mean_row(const DetectionEvalResult& result, Difficulty d) {
  const auto index = static_cast<int>(d);
  char head[64];
  std::snprintf(head, sizeof(head), "%-10s %-8s %5s", "mean", difficulty_name(d).c_str(), "");
  std::string row = head;
  for (const auto& level : result.mean) {
    const MeanAp& m = level[index];
    row += std::string(" |     ") + percent_cell(m.ap3d_r40) + percent_cell(m.ap3d_r11) + percent_cell(m.apbev_r40);
  }
  return row + '\n';
}

}  // namespace

nlohmann::json to_json(const DetectionEvalResult& result) {
  nlohmann::json json = {
      {"frames", result.frames}, {"difficulty_range_m", nlohmann::json::object()}, {"classes", nlohmann::json::object()}};
  for (Difficulty d : kDifficulties) json["difficulty_range_m"][difficulty_name(d)] = difficulty_range_m(d);
  for (const ClassResult& c : result.classes) {
    nlohmann::json& entry = json["classes"][io::object_class_name(c.object_class)];
    entry = {{"ground_truths", c.ground_truths}, {"predictions", c.predictions}};
    for (const ThresholdResult& level : c.levels) entry[iou_level_name(level.level)] = level_json(level);
  }
  nlohmann::json& mean = json["mean"];
  for (IouLevel level : kIouLevels) {
    for (Difficulty d : kDifficulties)
      mean[iou_level_name(level)][difficulty_name(d)] = mean_json(result.mean[static_cast<int>(level)][static_cast<int>(d)]);
  }
  return json;
}

std::string format_table(const DetectionEvalResult& result) {
  std::string table =
      "Detection AP (%), " + std::to_string(result.frames) + " frames; difficulty by distance: easy < 20 m, moderate < 30 m, hard < 50 m\n";
  table += "class      diff.       GT |  IoU  3D R40 3D R11 BEVR40 |  IoU  3D R40 3D R11 BEVR40\n";
  for (const ClassResult& c : result.classes) {
    for (Difficulty d : kDifficulties) table += class_row(c, d);
  }
  for (Difficulty d : kDifficulties) table += mean_row(result, d);
  return table;
}

}  // namespace mlidar::eval
