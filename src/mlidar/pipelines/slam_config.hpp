#pragma once
// Parameters of `mlidar slam` (the M-LOAM back end, thesis Ch. 4) and their
// strict reader for `--config mloam.yaml`. Defaults are Table 4.2:
//   sigma_R = 0.25, lambda_calib = 70, L_calib = 25, N = 4, p = 2, alpha = 1,
// and K = 300 (Sec. 4.6.2.1); Table 4.2's w (the mapping's uncertain-point filter) is not
// implemented and has no key. The documented example with every key is
// config/mloam.yaml. Every key is optional (absent = default); an unknown
// key, a wrong type or a value out of range throws InputError naming the
// file, the key (section.key) and the allowed range.
#include <filesystem>
#include <string>
#include <vector>

#include "mlidar/calib/convergence_monitor.hpp"
#include "mlidar/calib/online_hand_eye.hpp"
#include "mlidar/calib/extrinsic_check.hpp"
#include "mlidar/calib/shock_detector.hpp"
#include "mlidar/pipelines/slam_appearance_start.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {

/// The sliding window (Sec. 4.7) and mapping parameters.
struct WindowParams {
  int size = 4;                             ///< N: the window holds N + 1 states
  int pivot = 2;                            ///< p: the pivot state, origin of the local map, 1 <= p <= N
  double extrinsic_covariance_scale = 1.0;  ///< alpha >= 1: scale of the extrinsic covariance (10 under large perturbation)
  /// Refine the trusted odometry's poses in the sliding window (eq 4.22, slam_pose_window.hpp).
  bool refine_odometry = false;
  /// Extra re-matching passes of a calibration window at its last gate until the estimate settles (calibration_window.hpp).
  int calibration_settle_passes = 4;
};

/// How a LiDAR's calibration starts and starts again (beyond the thesis).
struct StartParams {
  std::size_t reinitialize_windows = 10;     ///< windows not accepted with a high residual ratio since the last acceptance (0: never)
  double reinitialize_residual_ratio = 2.0;  ///< high: the window's residual against the map above this times the base's own
  /// Pairs added with the rotation ready but not the translation before the
  /// window starts from the rotation and t = 0 (0: never).
  std::size_t zero_translation_after_pairs = 20;
  /// Frames after a LiDAR began initializing, and between two attempts, before it is calibrated by its appearance
  /// against the base's local maps on the frames kept since, as `calibrate auto` does (slam_appearance_start.hpp;
  /// 0: never). Also the frames kept: each attempt runs on the last of them.
  std::size_t appearance_after_frames = 100;
};

/// Uncertainty-aware mapping's inputs beyond slam::UncertaintyConfig: the extrinsic covariance used where the
/// extrinsics input gives none (1-sigma per axis, before alpha).
struct MappingParams {
  double extrinsic_prior_translation_m = 0.01;
  double extrinsic_prior_rotation_deg = 0.04;
};

/// Given extrinsics (`slam --calibrate fixed`, `odometry`) judged against the map: the `extrinsic_check:` section.
struct GivenExtrinsicChecks {
  /// Each auxiliary LiDAR's residual over the base's (calib/extrinsic_check.hpp); residual_ratio 0 turns every check off.
  calib::ExtrinsicCheckConfig residual;
  /// The map test (slam/map_consistency.hpp) after this many frames and again at twice as many each time (30, 60,
  /// 120, ...; 0: never; the odometry job: on its final map): a LiDAR's points map_ratio times farther from the other
  /// LiDARs' planes than from its own disagree. Doubling keeps its cost (about 50 ms for 4 LiDARs) off long runs.
  std::size_t map_first_frames = 30;
  double map_ratio = 3.0;
  /// A given extrinsic that disagrees is calibrated online from it, as `--calibrate refine` does (else only reported).
  bool recalibrate = true;
  bool enabled() const { return residual.residual_ratio > 0.0; }
};

struct SlamConfig {
  /// Eq 4.15-4.18; measured defaults beyond the thesis: the translation's predicted std gate and the planar start.
  calib::OnlineHandEyeConfig initialization{.translation_max_std_m = 0.1, .planar_rotation = true, .planar_min_pairs = 30};
  StartParams start;
  /// The appearance start's refinement and search (`calibrate auto`'s defaults; its `search` is initialization.appearance_search).
  AppearanceStartConfig appearance;
  /// Algorithm 1; the shared-error floor measured on the simulated protocol (docs/benchmarks.md "Extrinsic covariance").
  calib::ConvergenceConfig convergence{.bias_translation_sd_m = 0.01, .bias_rotation_sd_deg = 0.04, .outlier_mads = 3.0};
  WindowParams window;
  /// Re-calibration trigger; a rise below 2x is not a shock: a sustained 1.45-1.76x rise of one LiDAR's residual
  /// ratio in part of the simulated room fired a false trigger (43 m protocol, room seed 6), Table 4.6's shock is 6x.
  calib::ShockDetectorConfig shock{.min_relative_jump = 1.0};
  GivenExtrinsicChecks extrinsic_check;
  slam::OdometryConfig odometry;  ///< front end and scan-to-map registration; odometry.uncertainty is `mapping:`
  MappingParams mapping;
};

/// One documented key: "section.key", its allowed range in words, its meaning.
struct SlamConfigKey {
  std::string name;
  std::string range;
  std::string meaning;
};
/// Every key the reader accepts, in file order.
std::vector<SlamConfigKey> slam_config_keys();

/// Parses YAML text; `source` names the file in errors.
SlamConfig parse_slam_config(const std::string& yaml_text, const std::string& source);
/// Reads a file (InputError when missing or unreadable, or for any bad key).
SlamConfig read_slam_config(const std::filesystem::path& file);
/// Every key with its value, in the reader's format (parse_slam_config reads it back unchanged).
std::string slam_config_yaml(const SlamConfig& config);

}  // namespace mlidar::pipelines
