#include "mlidar/pipelines/slam_config.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <type_traits>
#include <variant>

#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/yaml_fields.hpp"

namespace mlidar::pipelines {
namespace {

struct Range {
  double lo = 0.0;
  double hi = 0.0;
  bool lo_open = false;
  bool hi_open = false;
  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
};

using Target = std::variant<double*, int*, std::size_t*, bool*, slam::SelectionMethod*>;

constexpr slam::SelectionMethod kSelectionMethods[] = {slam::SelectionMethod::kNone, slam::SelectionMethod::kRandom,
                                                       slam::SelectionMethod::kGreedy};

struct Field {
  const char* section;
  const char* key;
  Range range;  ///< unused for bool
  const char* meaning;
  Target target;
};

constexpr Range kPositive{0.0, 1e9, true, false};
constexpr Range kFraction{0.0, 1.0, true, true};

std::vector<Field> initialization_fields(SlamConfig& c) {
  calib::OnlineHandEyeConfig& init = c.initialization;
  return {
      {"initialization",
       "max_constraints",
       {2, 1e5},
       "K: motion pairs kept; when full the smallest rotation is dropped",
       &init.max_constraints},
      {"initialization", "rotation_threshold", kPositive, "sigma_R: rotation ready when sigma_min2(Q_K) exceeds it",
       &init.rotation_threshold},
      {"initialization",
       "huber_delta_rad",
       {0.0, 3.15, true, false},
       "eq 4.17 Huber threshold on the residual angle",
       &init.huber_delta_rad},
      {"initialization", "planar_ratio", kFraction, "planar motion below this eigenvalue ratio of eq 4.18", &init.planar_ratio},
      {"initialization", "translation_min_ratio", kFraction, "translation solvable above this ratio (< planar_ratio)",
       &init.translation_min_ratio},
      {"initialization", "translation_max_std_m", kPositive, "ready only when eq 4.18's predicted std of t is below this (m)",
       &init.translation_max_std_m},
      {"initialization",
       "translation_min_pairs",
       {2, 1e5},
       "fewer translation-valid pairs: translation not solved",
       &init.translation_min_pairs},
      {"initialization",
       "planar_rotation",
       {},
       "one rotation axis: start from eq 3.8-3.12, t along the axis from the ground",
       &init.planar_rotation},
      {"initialization", "planar_min_condition", kFraction, "eq 3.12 system's s_min / s_max needed for that start",
       &init.planar_min_condition},
      {"initialization",
       "planar_min_pairs",
       {3, 1e5},
       "fewer stored pairs: no planar start (few short pairs share an axis too)",
       &init.planar_min_pairs},
      {"initialization",
       "reinitialize_after_windows",
       {0, 1e5},
       "calibration windows not accepted with a high residual ratio before re-initializing (0: never)",
       &c.start.reinitialize_windows},
      {"initialization", "reinitialize_residual_ratio", kPositive, "high: the window's map residual above this times the base LiDAR's",
       &c.start.reinitialize_residual_ratio},
      {"initialization",
       "zero_translation_after_pairs",
       {0, 1e5},
       "pairs with the rotation ready but not the translation before the window starts from t = 0 (0: never)",
       &c.start.zero_translation_after_pairs},
      {"initialization",
       "appearance_after_frames",
       {0, 1e5},
       "frames initializing (and between attempts) before the LiDAR is calibrated by its appearance against the base's map (0: never)",
       &c.start.appearance_after_frames},
      {"initialization",
       "appearance_search",
       {},
       "the appearance start searches a start when the refinement from hand-eye's fails",
       &c.appearance.search},
  };
}

std::vector<Field> convergence_fields(SlamConfig& c) {
  return {
      {"convergence", "lambda_calib", kPositive, "accept a window's extrinsic when lambda_min exceeds it", &c.convergence.lambda_calib},
      {"convergence", "accepted_needed", {2, 1e5}, "L_calib: accepted estimates averaged at convergence", &c.convergence.accepted_needed},
      {"convergence",
       "bias_translation_sd_m",
       {0.0, 10.0},
       "per-axis 1-sigma (m) of the error all windows share, added to Xi_calib",
       &c.convergence.bias_translation_sd_m},
      {"convergence",
       "bias_rotation_sd_deg",
       {0.0, 180.0},
       "per-axis 1-sigma (deg) of the error all windows share, added to Xi_calib",
       &c.convergence.bias_rotation_sd_deg},
      {"convergence",
       "outlier_mads",
       {0.0, 100.0},
       "accepted estimates beyond this many robust sigmas of the median are left out of the mean (0: none)",
       &c.convergence.outlier_mads},
  };
}

std::vector<Field> window_fields(SlamConfig& c) {
  return {
      {"window", "size", {1, 100}, "N: the window holds N + 1 states", &c.window.size},
      {"window", "pivot", {1, 100}, "p: pivot state, origin of the local map (<= size)", &c.window.pivot},
      {"window",
       "extrinsic_covariance_scale",
       {1.0, 1e6},
       "alpha: scale of the extrinsic covariance",
       &c.window.extrinsic_covariance_scale},
      {"window", "refine_odometry", {}, "refine the trusted odometry's poses in the N + 1 window (eq 4.22)", &c.window.refine_odometry},
      {"window",
       "calibration_settle_passes",
       {0, 100},
       "extra re-matching passes of a calibration window until its estimate moves < 3 mm / 0.03 deg (0: two passes only)",
       &c.window.calibration_settle_passes},
  };
}

std::vector<Field> shock_fields(SlamConfig& c) {
  calib::ShockDetectorConfig& shock = c.shock;
  return {
      {"shock", "history", {3, 1e5}, "normal frames in the robust baseline", &shock.history},
      {"shock", "min_history", {3, 1e5}, "no decision before this many (<= history)", &shock.min_history},
      {"shock", "threshold_mads", {0.0, 100.0, true, false}, "robust z-score of a high frame", &shock.threshold_mads},
      {"shock", "min_relative_jump", {0.0, 100.0, true, false}, "and at least this relative residual rise", &shock.min_relative_jump},
      {"shock", "consecutive", {1, 1000}, "k: high frames in a row that trigger re-calibration", &shock.consecutive},
      {"shock", "relative_to_others", {}, "score against the other LiDARs' median residual", &shock.relative_to_others},
  };
}

std::vector<Field> extrinsic_check_fields(SlamConfig& c) {
  return {
      {"extrinsic_check",
       "frames",
       {1, 1e5},
       "frames in the median residual ratio of a given extrinsic",
       &c.extrinsic_check.residual.frames},
      {"extrinsic_check",
       "residual_ratio",
       {0.0, 100.0},
       "median ratio of a LiDAR's residual to the base's above which its given extrinsic disagrees with the map (0: no check)",
       &c.extrinsic_check.residual.residual_ratio},
      {"extrinsic_check",
       "map_first_frames",
       {0, 1e5},
       "frames before the first map test of the given extrinsics (each LiDAR's points against the others' planes), "
       "again at twice as many each time (0: never)",
       &c.extrinsic_check.map_first_frames},
      {"extrinsic_check",
       "map_ratio",
       {1.0, 1000.0},
       "a LiDAR's points this many times farther from the others' planes than from its own disagree",
       &c.extrinsic_check.map_ratio},
      {"extrinsic_check",
       "recalibrate",
       {},
       "calibrate a disagreeing extrinsic online from it (else report only)",
       &c.extrinsic_check.recalibrate},
  };
}

std::vector<Field> odometry_fields(SlamConfig& c) {
  slam::OdometryConfig& odo = c.odometry;
  return {
      {"odometry", "plane_voxel_m", {0.0, 100.0, true, false}, "voxel size of the local plane map", &odo.plane_voxel_m},
      {"odometry", "edge_voxel_m", {0.0, 100.0, true, false}, "voxel size of the local edge map", &odo.edge_voxel_m},
      {"odometry", "local_map_radius_m", {0.0, 1e4, true, false}, "voxels farther are dropped", &odo.local_map_radius_m},
      {"odometry", "max_iterations", {1, 1000}, "registration iterations per frame", &odo.registration.max_iterations},
      {"odometry",
       "restart_after_lost",
       {0, 1e6},
       "failed registrations in a row (frames without points not counted) after which the next frame with points starts a "
       "new local map at its predicted pose (0: never)",
       &odo.restart_after_lost},
      {"odometry",
       "restart_after_suspect",
       {0, 1e6},
       "frames with points in a row not trusted (suspect or lost) after which the next frame with points starts a new local "
       "map at its predicted pose (0: never)",
       &odo.restart_after_suspect},
      {"odometry",
       "refine_deskew",
       {},
       "deskew each frame again with the velocity its registration measured and register once more",
       &odo.refine_deskew},
      {"odometry",
       "deskew_in_registration",
       {},
       "deskew the features again between registration iterations with the velocity the estimate implies",
       &odo.deskew_in_registration},
      {"odometry",
       "recover_rows",
       {},
       "for clouds without a ring channel or model: recover each scan's rows from its elevations (else voxel samples as planes)",
       &odo.front_end.recover_rows},
      {"odometry",
       "recover_rows_max_skip",
       {0, 1000},
       "after a scan whose rows could not be recovered, that LiDAR's next 1, 2, 4, ... (at most this many) scans skip the search",
       &odo.front_end.recover_rows_max_skip},
      {"odometry",
       "plane_neighbors_max",
       {5, 8},
       "range-image features: a plane fits its 5 nearest map points, up to this many when the rest lie within plane_extra_radius_m",
       &odo.registration.plane_neighbors_max},
      {"odometry",
       "voxel_plane_neighbors_max",
       {5, 8},
       "plane_neighbors_max for a frame whose features are mostly voxel samples (clouds without a model or scan rows)",
       &odo.voxel_plane_neighbors_max},
      {"odometry",
       "voxel_coarse_stride",
       {1, 1000},
       "a frame whose features are mostly voxel samples first registers every n-th of them, then all from there (1: all at once)",
       &odo.voxel_coarse_stride},
      {"odometry",
       "plane_extra_radius_m",
       {0.0, 100.0},
       "the distance from the feature within which map points past the 5th nearest join its plane fit",
       &odo.registration.plane_extra_radius_m},
      {"odometry",
       "plane_min_extent_sigmas",
       {0.0, 10.0},
       "a plane's map neighbours must spread this many range sigmas (the noisiest LiDAR's) across; 0 turns the check off",
       &odo.plane_min_extent_sigmas},
      {"odometry",
       "huber_delta_m",
       {0.0, 100.0, true, false},
       "Huber scale on point residuals (eq 4.9's rho)",
       &odo.registration.huber_delta_m},
  };
}

std::vector<Field> selection_fields(SlamConfig& c) {
  slam::SelectionConfig& sel = c.odometry.registration.selection;
  return {
      {"selection", "method", {}, "none, random or greedy (Algorithm 2): which features the scan-to-map registration uses", &sel.method},
      {"selection", "ratio", {0.0, 1.0, true, false}, "M / N kept in a well-conditioned scene (thesis 0.2)", &sel.ratio},
      {"selection", "adaptive", {}, "keep degenerate_ratio of the features in a degenerate scene (sec 5.4.4)", &sel.adaptive},
      {"selection", "degenerate_ratio", {0.0, 1.0, true, false}, "M / N kept in a degenerate scene (thesis 0.8)", &sel.degenerate_ratio},
      {"selection",
       "degeneracy_threshold",
       {0.0, 1.0},
       "degenerate below this translation observability of all features' information",
       &sel.degeneracy_threshold},
      {"selection", "degeneracy_interval_s", kPositive, "the degeneracy (a search of every feature) is evaluated again after this long",
       &sel.degeneracy_interval_s},
      {"selection", "epsilon", kFraction, "decay factor: each greedy round draws N / M log(1 / epsilon) candidates", &sel.epsilon},
      {"selection",
       "time_budget_ms",
       {0.0, 1e6},
       "t_max: stop choosing after this long (0: no limit; a limit is not deterministic)",
       &sel.time_budget_ms},
      {"selection", "seed", {0, 9007199254740992.0}, "seed of the random draws", &sel.seed},
      {"selection", "min_features", {0, 1e9}, "never keep fewer features than this", &sel.min_features},
      {"selection",
       "held_out_share",
       {0.0, 10.0},
       "the result is checked on this share x M of the features it did not use",
       &sel.held_out_share},
      {"selection",
       "held_out_residual_ratio",
       {0.0, 1e6},
       "they disagree above this x the chosen features' mean |r| (plus the floor)",
       &sel.held_out_residual_ratio},
      {"selection",
       "held_out_residual_floor_m",
       {0.0, 100.0},
       "added to that bound (m); disagreeing, every feature is registered",
       &sel.held_out_residual_floor_m},
      {"selection",
       "max_frame_gap_s",
       {0.0, 1e6},
       "frames more than this long after the last registered one register every feature (s)",
       &sel.max_frame_gap_s},
      {"selection",
       "while_calibrating",
       {},
       "select also while an extrinsic is calibrated (online or refine; else every feature until all LiDARs are trusted)",
       &sel.while_calibrating},
  };
}

std::vector<Field> mapping_fields(SlamConfig& c) {
  slam::UncertaintyConfig& ua = c.odometry.uncertainty;
  return {
      {"mapping",
       "uncertainty_aware",
       {},
       "weight registration rows by each point's covariance and keep uncertain points out of the map (sec 4.8)",
       &ua.enabled},
      {"mapping",
       "trace_threshold_m2",
       {0.0, 1e6, true, false},
       "w (m^2): points with tr(Sigma) above it do not enter the map",
       &ua.trace_threshold_m2},
      {"mapping",
       "residual_sigma_m",
       {0.0, 100.0, true, false},
       "sigma_0 (m): a certain point's residual against the map",
       &ua.residual_sigma_m},
      {"mapping", "range_sigma_m", {0.0, 10.0}, "range noise 1-sigma (m) where the LiDAR model gives none", &ua.range_sigma_m},
      {"mapping", "angular_sigma_rad", {0.0, 0.1}, "bearing noise 1-sigma (rad) per axis", &ua.angular_sigma_rad},
      {"mapping",
       "voxel_filter_m",
       {0.0, 100.0},
       "eq 4.30 cube edge (m) for a frame's points before they enter the map (0: off)",
       &ua.voxel_filter_m},
      {"mapping",
       "extrinsic_prior_translation_m",
       {0.0, 100.0},
       "extrinsic 1-sigma (m) per axis where the extrinsics input has no covariance (before alpha)",
       &c.mapping.extrinsic_prior_translation_m},
      {"mapping",
       "extrinsic_prior_rotation_deg",
       {0.0, 180.0},
       "extrinsic 1-sigma (deg) per axis where the extrinsics input has no covariance (before alpha)",
       &c.mapping.extrinsic_prior_rotation_deg},
  };
}

/// The schema: one row per key, bound to `c`'s members, section by section.
std::vector<Field> fields(SlamConfig& c) {
  std::vector<Field> all;
  for (auto* section :
       {&initialization_fields, &convergence_fields, &window_fields, &shock_fields, &extrinsic_check_fields, &odometry_fields, &selection_fields, &mapping_fields}) {
    const std::vector<Field> rows = section(c);
    all.insert(all.end(), rows.begin(), rows.end());
  }
  return all;
}

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string short_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

std::string range_text(const Field& f) {
  if (std::holds_alternative<bool*>(f.target)) return "true or false";
  if (std::holds_alternative<slam::SelectionMethod*>(f.target)) return "none, random or greedy";
  const bool integer = !std::holds_alternative<double*>(f.target);
  return std::string(integer ? "an integer in " : "a number in ") + (f.range.lo_open ? "(" : "[") + short_number(f.range.lo) + ", " +
         short_number(f.range.hi) + (f.range.hi_open ? ")" : "]");
}

std::string value_text(const Field& f) {
  return std::visit(
      [](auto* p) -> std::string {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, bool>)
          return *p ? "true" : "false";
        else if constexpr (std::is_same_v<T, slam::SelectionMethod>)
          return slam::selection_method_name(*p);
        else if constexpr (std::is_same_v<T, double>)
          return number_text(*p);
        else
          return std::to_string(*p);
      },
      f.target);
}

void read_field(const io::YamlFields& yaml, const YAML::Node& node, const Field& f) {
  const std::string key = std::string(f.section) + "." + f.key;
  const auto wrong = [&] {
    const std::string got = node.IsScalar() ? ", got '" + node.Scalar() + "'" : "";
    yaml.fail(key, "expected " + range_text(f) + got);
  };
  if (!node.IsScalar()) wrong();
  if (bool* const* flag = std::get_if<bool*>(&f.target)) {
    if (!YAML::convert<bool>::decode(node, **flag)) wrong();
    return;
  }
  if (slam::SelectionMethod* const* method = std::get_if<slam::SelectionMethod*>(&f.target)) {
    for (const slam::SelectionMethod m : kSelectionMethods) {
      if (node.Scalar() == slam::selection_method_name(m)) {
        **method = m;
        return;
      }
    }
    wrong();
  }
  double value = 0.0;
  if (!YAML::convert<double>::decode(node, value) || !std::isfinite(value) || !f.range.contains(value)) wrong();
  if (double* const* number = std::get_if<double*>(&f.target)) {
    **number = value;
    return;
  }
  if (std::floor(value) != value) wrong();
  if (int* const* i = std::get_if<int*>(&f.target)) **i = static_cast<int>(value);
  if (std::size_t* const* n = std::get_if<std::size_t*>(&f.target)) **n = static_cast<std::size_t>(value);
}

/// Limits that tie two keys together.
void check_relations(const io::YamlFields& yaml, const SlamConfig& c) {
  if (c.window.pivot > c.window.size) {
    yaml.fail("window.pivot", "expected an integer in [1, window.size = " + std::to_string(c.window.size) + "]");
  }
  if (c.shock.min_history > c.shock.history) {
    yaml.fail("shock.min_history", "expected an integer in [3, shock.history = " + std::to_string(c.shock.history) + "]");
  }
  if (c.initialization.translation_min_ratio >= c.initialization.planar_ratio) {
    yaml.fail("initialization.translation_min_ratio",
              "expected a number in (0, initialization.planar_ratio = " + short_number(c.initialization.planar_ratio) + ")");
  }
}

}  // namespace

std::vector<SlamConfigKey> slam_config_keys() {
  SlamConfig defaults;
  std::vector<SlamConfigKey> keys;
  for (const Field& f : fields(defaults)) {
    keys.push_back({std::string(f.section) + "." + f.key, range_text(f), f.meaning});
  }
  return keys;
}

SlamConfig parse_slam_config(const std::string& yaml_text, const std::string& source) {
  const io::YamlFields yaml(source, "config/mloam.yaml");
  const YAML::Node root = yaml.load(yaml_text);
  SlamConfig config;
  if (!root || root.IsNull()) return config;  // an empty file: all defaults
  const std::vector<Field> schema = fields(config);
  std::set<std::string> sections;
  for (const Field& f : schema) sections.insert(f.section);
  yaml.only_keys(root, "", sections);
  for (const std::string& section : sections) {
    const YAML::Node node = root[section];
    if (!node) continue;
    std::set<std::string> keys;
    for (const Field& f : schema) {
      if (section == f.section) keys.insert(f.key);
    }
    yaml.only_keys(node, section, keys);
    for (const Field& f : schema) {
      if (section == f.section && node[f.key]) read_field(yaml, node[f.key], f);
    }
  }
  check_relations(yaml, config);
  return config;
}

SlamConfig read_slam_config(const std::filesystem::path& file) { return parse_slam_config(io::read_file_text(file), file.string()); }

std::string slam_config_yaml(const SlamConfig& config) {
  SlamConfig copy = config;
  std::string text;
  std::string section;
  for (const Field& f : fields(copy)) {
    if (section != f.section) {
      section = f.section;
      text += section + ":\n";
    }
    text += std::string("  ") + f.key + ": " + value_text(f) + "\n";
  }
  return text;
}

}  // namespace mlidar::pipelines
