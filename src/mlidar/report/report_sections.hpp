#pragma once
// The sections of report.html (run_report.hpp), each from a RunData; a
// section the run has no data for is absent. Internal to mlidar::report.
#include <optional>
#include <string>
#include <vector>

#include "mlidar/core/fixed_decimals.hpp"
#include "mlidar/report/run_report.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::report {

struct Section {
  std::string id;  ///< the HTML id (tests and links find a section by it)
  std::string title;
  std::string html;  ///< its body
};

/// The whole page: head with the style, the title, a link per section, the sections.
std::string render_page(const std::string& title, const std::vector<Section>& sections);

/// A 640 x 480 chart with equal axes over axes `horizontal` and `vertical` (0 x, 1 y, 2 z, in m): a top or side view.
Chart spatial_view(const std::string& title, int horizontal, int vertical);

/// A table whose cells are given as HTML (escape text first).
std::string html_table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);

/// A number of a JSON value, NaN when it is null or not a number.
double number_of(const nlohmann::json& value);

/// {translation, quaternion_wxyz} as written by the jobs; nullopt when absent or malformed.
std::optional<SE3> pose_of(const nlohmann::json& json);

Section summary_section(const RunData& run);
std::optional<Section> extrinsics_section(const RunData& run);
std::optional<Section> trajectory_section(const RunData& run);
/// One per LiDAR calibrated online (slam's per-frame windows).
std::vector<Section> calibration_sections(const RunData& run);
std::optional<Section> timing_section(const RunData& run);
/// The map's top view coloured by height.
std::optional<Section> map_section(const RunData& run);
/// eval traj: the error statistics, the KITTI drift per segment length and the pose NEES of eval.json.
std::optional<Section> evaluation_section(const RunData& run);
/// calibrate auto: hand-eye's estimate, the refinement's start and its result per LiDAR.
std::optional<Section> autocalib_stages_section(const RunData& run);

}  // namespace mlidar::report
