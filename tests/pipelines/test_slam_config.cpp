// `mlidar slam --config`: Table 4.2 defaults, the documented example, a
// write/read round trip and each kind of rejection.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/pipelines/slam_config.hpp"
#include "test_support.hpp"

namespace mlidar::pipelines {
namespace {

const std::filesystem::path kExample = std::filesystem::path(MLIDAR_SOURCE_DIR) / "config" / "mloam.yaml";

TEST(SlamConfig, DefaultsAreTable42) {
  const SlamConfig c;
  EXPECT_EQ(c.initialization.rotation_threshold, 0.25);  // sigma_R
  EXPECT_EQ(c.convergence.lambda_calib, 70.0);
  EXPECT_EQ(c.convergence.accepted_needed, 25u);         // L_calib
  EXPECT_EQ(c.convergence.bias_translation_sd_m, 0.01);  // measured shared-error floor (docs/benchmarks.md)
  EXPECT_EQ(c.convergence.bias_rotation_sd_deg, 0.04);
  EXPECT_EQ(c.shock.min_relative_jump, 1.0);            // 2x: a 1.5-1.8x rise in part of a room is not a shock
  EXPECT_EQ(c.window.size, 4);                          // N
  EXPECT_EQ(c.window.pivot, 2);                         // p
  EXPECT_EQ(c.window.extrinsic_covariance_scale, 1.0);  // alpha
  EXPECT_EQ(c.initialization.max_constraints, 300u);    // K
}

TEST(SlamConfig, ExampleFileDocumentsEveryKeyWithItsDefault) {
  const std::string text = io::read_file_text(kExample);
  EXPECT_EQ(slam_config_yaml(read_slam_config(kExample)), slam_config_yaml(SlamConfig{}));
  for (const SlamConfigKey& key : slam_config_keys()) {
    const std::string leaf = key.name.substr(key.name.find('.') + 1);
    EXPECT_NE(text.find("\n  " + leaf + ":"), std::string::npos) << key.name;
    EXPECT_FALSE(key.range.empty());
    EXPECT_FALSE(key.meaning.empty());
  }
  EXPECT_EQ(slam_config_keys().size(), 75u);
}

TEST(SlamConfig, EmptyDocumentAndPartialSectionsKeepDefaults) {
  EXPECT_EQ(slam_config_yaml(parse_slam_config("", "empty.yaml")), slam_config_yaml(SlamConfig{}));
  const SlamConfig c = parse_slam_config("window:\n  size: 6\n", "partial.yaml");
  EXPECT_EQ(c.window.size, 6);
  EXPECT_EQ(c.window.pivot, 2);
  EXPECT_EQ(c.convergence.lambda_calib, 70.0);
}

TEST(SlamConfig, RoundTripsEveryKey) {
  // Named members (not aggregate positions), so a reordered struct still puts each value in its own field.
  SlamConfig c;
  c.initialization.max_constraints = 123;
  c.initialization.rotation_threshold = 0.5;
  c.initialization.huber_delta_rad = 0.1 / 3.0;
  c.initialization.planar_ratio = 0.07;
  c.initialization.translation_min_ratio = 0.002;
  c.convergence.lambda_calib = 65.5;
  c.convergence.accepted_needed = 30;
  c.window.size = 6;
  c.window.pivot = 3;
  c.window.extrinsic_covariance_scale = 10.0;
  c.window.refine_odometry = true;
  c.shock.history = 80;
  c.shock.min_history = 30;
  c.shock.threshold_mads = 3.5;
  c.shock.min_relative_jump = 0.4;
  c.shock.consecutive = 7;
  c.shock.relative_to_others = false;
  c.odometry.plane_voxel_m = 0.7;
  c.odometry.edge_voxel_m = 0.3;
  c.odometry.local_map_radius_m = 80.0;
  c.odometry.registration.max_iterations = 12;
  c.odometry.restart_after_lost = 7;
  c.odometry.restart_after_suspect = 13;
  c.odometry.registration.huber_delta_m = 0.05;
  c.odometry.refine_deskew = true;
  c.odometry.registration.selection.method = slam::SelectionMethod::kRandom;
  c.odometry.registration.selection.ratio = 0.3;
  c.odometry.registration.selection.epsilon = 0.25;
  c.odometry.registration.selection.seed = 77;
  c.odometry.registration.selection.while_calibrating = true;
  const std::string text = slam_config_yaml(c);
  EXPECT_NE(text, slam_config_yaml(SlamConfig{}));
  const SlamConfig back = parse_slam_config(text, "written.yaml");
  EXPECT_EQ(slam_config_yaml(back), text);
  EXPECT_EQ(back.initialization.huber_delta_rad, 0.1 / 3.0);  // 17 digits: exact
  EXPECT_EQ(back.initialization.max_constraints, 123u);
  EXPECT_EQ(back.initialization.rotation_threshold, 0.5);
  EXPECT_EQ(back.initialization.planar_ratio, 0.07);
  EXPECT_EQ(back.initialization.translation_min_ratio, 0.002);
  EXPECT_EQ(back.convergence.lambda_calib, 65.5);
  EXPECT_EQ(back.convergence.accepted_needed, 30u);
  EXPECT_EQ(back.window.size, 6);
  EXPECT_EQ(back.window.pivot, 3);
  EXPECT_EQ(back.window.extrinsic_covariance_scale, 10.0);
  EXPECT_FALSE(back.shock.relative_to_others);
  EXPECT_TRUE(back.window.refine_odometry);
  EXPECT_EQ(back.odometry.registration.max_iterations, 12);
  EXPECT_EQ(back.odometry.restart_after_lost, 7u);
  EXPECT_EQ(back.odometry.restart_after_suspect, 13u);
  EXPECT_EQ(back.odometry.registration.huber_delta_m, 0.05);
  EXPECT_TRUE(back.odometry.refine_deskew);
  EXPECT_EQ(back.odometry.registration.selection.method, slam::SelectionMethod::kRandom);
  EXPECT_EQ(back.odometry.registration.selection.ratio, 0.3);
  EXPECT_EQ(back.odometry.registration.selection.epsilon, 0.25);
  EXPECT_EQ(back.odometry.registration.selection.seed, 77u);
  EXPECT_TRUE(back.odometry.registration.selection.while_calibrating);
}

// A write/read round trip is symmetric: a key bound to the wrong member reads back as written. Here the
// file is written by hand and every key's value is looked for in the member of that name.
TEST(SlamConfig, EachKeyOfAHandWrittenFileLandsInTheMemberOfItsName) {
  const std::string text =
      "initialization:\n"
      "  max_constraints: 123\n  rotation_threshold: 0.5\n  huber_delta_rad: 0.03\n  planar_ratio: 0.07\n"
      "  translation_min_ratio: 0.002\n  translation_max_std_m: 0.4\n  translation_min_pairs: 5\n  planar_rotation: false\n"
      "  planar_min_condition: 0.004\n  planar_min_pairs: 31\n  reinitialize_after_windows: 11\n"
      "  reinitialize_residual_ratio: 2.5\n  zero_translation_after_pairs: 21\n  appearance_after_frames: 40\n"
      "  appearance_search: false\n"
      "convergence:\n"
      "  lambda_calib: 65.5\n  accepted_needed: 30\n  bias_translation_sd_m: 0.02\n  bias_rotation_sd_deg: 0.06\n"
      "  outlier_mads: 2.5\n"
      "window:\n"
      "  size: 6\n  pivot: 3\n  extrinsic_covariance_scale: 10\n  refine_odometry: true\n  calibration_settle_passes: 7\n"
      "shock:\n"
      "  history: 80\n  min_history: 30\n  threshold_mads: 3.5\n  min_relative_jump: 0.4\n  consecutive: 7\n"
      "  relative_to_others: false\n"
      "extrinsic_check:\n"
      "  frames: 15\n  residual_ratio: 2.5\n  map_first_frames: 40\n  map_ratio: 4\n  recalibrate: false\n"
      "odometry:\n"
      "  plane_voxel_m: 0.7\n  edge_voxel_m: 0.3\n  local_map_radius_m: 80\n  max_iterations: 12\n  refine_deskew: true\n"
      "  deskew_in_registration: false\n  plane_neighbors_max: 8\n  voxel_plane_neighbors_max: 6\n  plane_extra_radius_m: 0.3\n"
      "  plane_min_extent_sigmas: 0.8\n  huber_delta_m: 0.05\n"
      "  recover_rows: false\n  recover_rows_max_skip: 4\n  voxel_coarse_stride: 3\n  restart_after_lost: 9\n"
      "  restart_after_suspect: 11\n"
      "selection:\n"
      "  method: greedy\n  ratio: 0.3\n  adaptive: false\n  degenerate_ratio: 0.7\n  degeneracy_threshold: 0.25\n"
      "  degeneracy_interval_s: 2\n  epsilon: 0.4\n  time_budget_ms: 3\n  seed: 12\n  min_features: 40\n"
      "  held_out_share: 0.5\n  held_out_residual_ratio: 2\n  held_out_residual_floor_m: 0.02\n  max_frame_gap_s: 0.6\n"
      "  while_calibrating: true\n"
      "mapping:\n"
      "  uncertainty_aware: true\n  trace_threshold_m2: 0.3\n  residual_sigma_m: 0.07\n  range_sigma_m: 0.05\n"
      "  angular_sigma_rad: 0.002\n  voxel_filter_m: 0.25\n  extrinsic_prior_translation_m: 0.03\n"
      "  extrinsic_prior_rotation_deg: 1.5\n";
  for (const SlamConfigKey& key : slam_config_keys()) {  // every key, each set to a value other than its default
    const std::string section = key.name.substr(0, key.name.find('.'));
    const std::string leaf = key.name.substr(key.name.find('.') + 1);
    const std::size_t section_start = text.find(section + ":\n");
    ASSERT_NE(section_start, std::string::npos) << key.name;
    EXPECT_NE(text.find("  " + leaf + ": ", section_start), std::string::npos) << key.name;
  }
  const SlamConfig c = parse_slam_config(text, "by_hand.yaml");
  EXPECT_EQ(c.initialization.max_constraints, 123u);
  EXPECT_EQ(c.initialization.rotation_threshold, 0.5);
  EXPECT_EQ(c.initialization.huber_delta_rad, 0.03);
  EXPECT_EQ(c.initialization.planar_ratio, 0.07);
  EXPECT_EQ(c.initialization.translation_min_ratio, 0.002);
  EXPECT_EQ(c.initialization.translation_max_std_m, 0.4);
  EXPECT_EQ(c.initialization.translation_min_pairs, 5u);
  EXPECT_FALSE(c.initialization.planar_rotation);
  EXPECT_EQ(c.initialization.planar_min_condition, 0.004);
  EXPECT_EQ(c.initialization.planar_min_pairs, 31u);
  EXPECT_EQ(c.start.reinitialize_windows, 11u);
  EXPECT_EQ(c.start.reinitialize_residual_ratio, 2.5);
  EXPECT_EQ(c.start.zero_translation_after_pairs, 21u);
  EXPECT_EQ(c.start.appearance_after_frames, 40u);
  EXPECT_FALSE(c.appearance.search);
  EXPECT_EQ(c.convergence.lambda_calib, 65.5);
  EXPECT_EQ(c.convergence.accepted_needed, 30u);
  EXPECT_EQ(c.convergence.bias_translation_sd_m, 0.02);
  EXPECT_EQ(c.convergence.bias_rotation_sd_deg, 0.06);
  EXPECT_EQ(c.convergence.outlier_mads, 2.5);
  EXPECT_EQ(c.window.size, 6);
  EXPECT_EQ(c.window.pivot, 3);
  EXPECT_EQ(c.window.extrinsic_covariance_scale, 10.0);
  EXPECT_TRUE(c.window.refine_odometry);
  EXPECT_EQ(c.window.calibration_settle_passes, 7);
  EXPECT_EQ(c.shock.history, 80u);
  EXPECT_EQ(c.shock.min_history, 30u);
  EXPECT_EQ(c.shock.threshold_mads, 3.5);
  EXPECT_EQ(c.shock.min_relative_jump, 0.4);
  EXPECT_EQ(c.shock.consecutive, 7u);
  EXPECT_FALSE(c.shock.relative_to_others);
  EXPECT_EQ(c.extrinsic_check.residual.frames, 15u);
  EXPECT_EQ(c.extrinsic_check.residual.residual_ratio, 2.5);
  EXPECT_EQ(c.extrinsic_check.map_first_frames, 40u);
  EXPECT_EQ(c.extrinsic_check.map_ratio, 4.0);
  EXPECT_FALSE(c.extrinsic_check.recalibrate);
  EXPECT_EQ(c.odometry.plane_voxel_m, 0.7);
  EXPECT_EQ(c.odometry.edge_voxel_m, 0.3);
  EXPECT_EQ(c.odometry.local_map_radius_m, 80.0);
  EXPECT_EQ(c.odometry.registration.max_iterations, 12);
  EXPECT_EQ(c.odometry.restart_after_lost, 9u);
  EXPECT_EQ(c.odometry.restart_after_suspect, 11u);
  EXPECT_TRUE(c.odometry.refine_deskew);
  EXPECT_FALSE(c.odometry.deskew_in_registration);
  const slam::SelectionConfig& sel = c.odometry.registration.selection;
  EXPECT_EQ(sel.method, slam::SelectionMethod::kGreedy);
  EXPECT_EQ(sel.ratio, 0.3);
  EXPECT_FALSE(sel.adaptive);
  EXPECT_EQ(sel.degenerate_ratio, 0.7);
  EXPECT_EQ(sel.degeneracy_threshold, 0.25);
  EXPECT_EQ(sel.degeneracy_interval_s, 2.0);
  EXPECT_EQ(sel.epsilon, 0.4);
  EXPECT_EQ(sel.time_budget_ms, 3.0);
  EXPECT_EQ(sel.seed, 12u);
  EXPECT_EQ(sel.min_features, 40u);
  EXPECT_EQ(sel.held_out_share, 0.5);
  EXPECT_EQ(sel.held_out_residual_ratio, 2.0);
  EXPECT_EQ(sel.held_out_residual_floor_m, 0.02);
  EXPECT_EQ(sel.max_frame_gap_s, 0.6);
  EXPECT_TRUE(sel.while_calibrating);
  EXPECT_EQ(c.odometry.registration.plane_neighbors_max, 8);
  EXPECT_EQ(c.odometry.voxel_plane_neighbors_max, 6);
  EXPECT_EQ(c.odometry.registration.plane_extra_radius_m, 0.3);
  EXPECT_EQ(c.odometry.plane_min_extent_sigmas, 0.8);
  EXPECT_EQ(c.odometry.registration.huber_delta_m, 0.05);
  EXPECT_FALSE(c.odometry.front_end.recover_rows);
  EXPECT_EQ(c.odometry.front_end.recover_rows_max_skip, 4);
  EXPECT_EQ(c.odometry.voxel_coarse_stride, 3);
  const slam::UncertaintyConfig& ua = c.odometry.uncertainty;
  EXPECT_TRUE(ua.enabled);
  EXPECT_EQ(ua.trace_threshold_m2, 0.3);
  EXPECT_EQ(ua.residual_sigma_m, 0.07);
  EXPECT_EQ(ua.range_sigma_m, 0.05);
  EXPECT_EQ(ua.angular_sigma_rad, 0.002);
  EXPECT_EQ(ua.voxel_filter_m, 0.25);
  EXPECT_EQ(c.mapping.extrinsic_prior_translation_m, 0.03);
  EXPECT_EQ(c.mapping.extrinsic_prior_rotation_deg, 1.5);
}

struct Rejection {
  std::string yaml;
  std::string field;
  std::string words;  ///< expected in the message
};

TEST(SlamConfig, RejectsWithFileKeyAndRange) {
  const std::vector<Rejection> cases = {
      {"windw:\n  size: 4\n", "windw", "unknown key"},
      {"window:\n  sise: 4\n", "window.sise", "unknown key"},
      {"window:\n  uncertainty_threshold: 100\n", "window.uncertainty_threshold", "unknown key"},  // Table 4.2's w: never implemented
      {"window: 4\n", "window", "expected a mapping"},
      {"window:\n  size: four\n", "window.size", "an integer in [1, 100], got 'four'"},
      {"window:\n  size: 4.5\n", "window.size", "an integer in [1, 100]"},
      {"window:\n  size: 0\n", "window.size", "an integer in [1, 100]"},
      {"window:\n  size: [4]\n", "window.size", "an integer in [1, 100]"},
      {"window:\n  size: 3\n  pivot: 4\n", "window.pivot", "[1, window.size = 3]"},
      {"window:\n  extrinsic_covariance_scale: 0.5\n", "window.extrinsic_covariance_scale", "a number in [1, 1e+06]"},
      {"initialization:\n  rotation_threshold: 0\n", "initialization.rotation_threshold", "a number in (0, 1e+09]"},
      {"initialization:\n  rotation_threshold: .nan\n", "initialization.rotation_threshold", "a number in (0, 1e+09]"},
      {"initialization:\n  planar_ratio: 1\n", "initialization.planar_ratio", "a number in (0, 1)"},
      {"initialization:\n  translation_min_ratio: 0.06\n", "initialization.translation_min_ratio",
       "(0, initialization.planar_ratio = 0.05)"},
      {"initialization:\n  max_constraints: -1\n", "initialization.max_constraints", "an integer in [2, 100000]"},
      {"initialization:\n  translation_max_std_m: 0\n", "initialization.translation_max_std_m", "a number in (0, 1e+09]"},
      {"initialization:\n  planar_rotation: 2\n", "initialization.planar_rotation", "true or false, got '2'"},
      {"initialization:\n  reinitialize_after_windows: 1.5\n", "initialization.reinitialize_after_windows", "an integer in [0, 100000]"},
      {"initialization:\n  zero_translation_after_pairs: -1\n", "initialization.zero_translation_after_pairs", "an integer in [0, 100000]"},
      {"convergence:\n  lambda_calib: -70\n", "convergence.lambda_calib", "a number in (0, 1e+09]"},
      {"convergence:\n  accepted_needed: 1\n", "convergence.accepted_needed", "an integer in [2, 100000]"},
      {"shock:\n  relative_to_others: maybe\n", "shock.relative_to_others", "true or false, got 'maybe'"},
      {"shock:\n  history: 10\n", "shock.min_history", "[3, shock.history = 10]"},
      {"odometry:\n  max_iterations: 0\n", "odometry.max_iterations", "an integer in [1, 1000]"},
      {"selection:\n  method: best\n", "selection.method", "none, random or greedy, got 'best'"},
      {"selection:\n  method: [greedy]\n", "selection.method", "none, random or greedy"},
      {"selection:\n  ratio: 0\n", "selection.ratio", "a number in (0, 1]"},
      {"selection:\n  epsilon: 1\n", "selection.epsilon", "a number in (0, 1)"},
      {"window: {size: 4\n", "(document)", "not valid YAML"},
  };
  for (const Rejection& r : cases) {
    try {
      parse_slam_config(r.yaml, "bad/mloam.yaml");
      ADD_FAILURE() << "accepted: " << r.yaml;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "bad/mloam.yaml") << r.yaml;
      EXPECT_EQ(e.field(), r.field) << r.yaml;
      EXPECT_NE(std::string(e.what()).find(r.words), std::string::npos) << e.what();
    }
  }
}

TEST(SlamConfig, MissingFileIsAnInputError) { EXPECT_THROW(read_slam_config(test::scratch_dir() / "no_such_mloam.yaml"), InputError); }

}  // namespace
}  // namespace mlidar::pipelines
