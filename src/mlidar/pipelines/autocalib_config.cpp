#include "mlidar/pipelines/autocalib_config.hpp"

#include <cmath>

#include "mlidar/io/yaml_fields.hpp"

namespace mlidar::pipelines {
namespace {

/// Sets `value` from map[key] when present, a number in [lo, hi].
void read_number(const io::YamlFields& fields, const YAML::Node& map, const std::string& prefix, const std::string& key, double lo,
                 double hi, double& value) {
  if (map[key]) value = fields.number_in(map[key], prefix + key, lo, hi);
}

/// Sets `value` from map[key] when present, a whole number in [lo, hi].
template <typename Int>
void read_integer(const io::YamlFields& fields, const YAML::Node& map, const std::string& prefix, const std::string& key, Int lo, Int hi,
                  Int& value) {
  if (!map[key]) return;
  const double number = fields.number_in(map[key], prefix + key, static_cast<double>(lo), static_cast<double>(hi));
  if (number != std::floor(number)) fields.fail(prefix + key, "expected a whole number");
  value = static_cast<Int>(number);
}

void read_handeye(const io::YamlFields& fields, const YAML::Node& map, calib::HandEyeConfig& config) {
  fields.only_keys(map, "handeye", {"screw_angle_tolerance_rad", "screw_pitch_tolerance_m", "planar_singular_ratio"});
  read_number(fields, map, "handeye.", "screw_angle_tolerance_rad", 0.0, 3.2, config.screw_angle_tolerance_rad);
  read_number(fields, map, "handeye.", "screw_pitch_tolerance_m", 0.0, 100.0, config.screw_pitch_tolerance_m);
  read_number(fields, map, "handeye.", "planar_singular_ratio", 0.0, 1.0, config.planar_singular_ratio);
}

void read_refine(const io::YamlFields& fields, const YAML::Node& map, RefineConfig& config) {
  fields.only_keys(map, "refine",
                   {"frame_step", "window", "overlap_radius_m", "min_overlap", "relative_overlap", "coarse_correspondence_m",
                    "fine_correspondence_m", "min_match_ratio", "min_candidates", "max_fused_translation_sd_m", "max_fused_rotation_sd_deg",
                    "fusion_passes", "keep_fraction", "min_keep", "bias_translation_sd_m", "bias_rotation_sd_deg"});
  const std::string p = "refine.";
  read_integer(fields, map, p, "frame_step", 1, 100000, config.frame_step);
  read_integer(fields, map, p, "window", 0, 1000, config.window);
  read_number(fields, map, p, "overlap_radius_m", 1e-3, 100.0, config.overlap_radius_m);
  read_number(fields, map, p, "min_overlap", 0.0, 1.0, config.min_overlap);
  read_number(fields, map, p, "relative_overlap", 0.0, 1.0, config.relative_overlap);
  read_number(fields, map, p, "coarse_correspondence_m", 1e-3, 100.0, config.coarse_correspondence_m);
  read_number(fields, map, p, "fine_correspondence_m", 1e-3, 100.0, config.fine_correspondence_m);
  read_number(fields, map, p, "min_match_ratio", 0.0, 1.0, config.min_match_ratio);
  read_integer(fields, map, p, "min_candidates", std::size_t{1}, std::size_t{100000}, config.min_candidates);
  read_number(fields, map, p, "max_fused_translation_sd_m", 0.0, 100.0, config.max_fused_translation_sd_m);
  read_number(fields, map, p, "max_fused_rotation_sd_deg", 0.0, 180.0, config.max_fused_rotation_sd_deg);
  read_integer(fields, map, p, "fusion_passes", 1, 100, config.fusion_passes);
  read_number(fields, map, p, "keep_fraction", 1e-3, 1.0, config.selection.keep_fraction);
  read_integer(fields, map, p, "min_keep", std::size_t{1}, std::size_t{100000}, config.selection.min_keep);
  read_number(fields, map, p, "bias_translation_sd_m", 0.0, 10.0, config.selection.bias_translation_sd_m);
  read_number(fields, map, p, "bias_rotation_sd_deg", 0.0, 90.0, config.selection.bias_rotation_sd_deg);
}

void read_search(const io::YamlFields& fields, const YAML::Node& map, AutoCalibJob& job) {
  fields.only_keys(map, "search", {"enabled", "frames", "map_window", "mount_radius_m", "xy_radius_m", "xy_step_m", "yaw_step_deg"});
  const std::string p = "search.";
  if (map["enabled"]) {
    const std::string enabled = fields.text(map["enabled"], p + "enabled");
    if (enabled != "true" && enabled != "false") fields.fail(p + "enabled", "expected true or false, got '" + enabled + "'");
    job.search = enabled == "true";
  }
  StartSearchConfig& config = job.start_search;
  read_integer(fields, map, p, "frames", std::size_t{1}, std::size_t{1000}, config.frames);
  read_integer(fields, map, p, "map_window", 0, 1000, config.map_window);
  read_number(fields, map, p, "mount_radius_m", 0.0, 1000.0, config.mount_radius_m);
  read_number(fields, map, p, "xy_radius_m", 0.0, 100.0, config.coarse.xy_radius_m);
  read_number(fields, map, p, "xy_step_m", 0.05, 100.0, config.coarse.xy_step_m);
  read_number(fields, map, p, "yaw_step_deg", 1.0, 180.0, config.coarse.yaw_step_deg);
}

}  // namespace

AutoCalibJob apply_autocalib_config(const std::string& yaml_text, const std::string& source, AutoCalibJob job) {
  const io::YamlFields fields(source, "auto.yaml");
  const YAML::Node root = fields.load(yaml_text);
  if (!root || root.IsNull()) return job;  // an empty file keeps every default
  fields.only_keys(root, "", {"pair_stride", "ground_frames", "handeye", "refine", "search"});
  read_integer(fields, root, "", "pair_stride", 1, 100000, job.pair_stride);
  read_integer(fields, root, "", "ground_frames", 0, 100000, job.ground_frames);
  if (root["handeye"]) read_handeye(fields, root["handeye"], job.hand_eye);
  if (root["refine"]) read_refine(fields, root["refine"], job.refine);
  if (root["search"]) read_search(fields, root["search"], job);
  return job;
}

}  // namespace mlidar::pipelines
