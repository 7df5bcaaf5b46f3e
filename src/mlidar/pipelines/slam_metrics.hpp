#pragma once
// metrics.json of `mlidar slam`:
//   frames, calibrate ("online" | "fixed"), lidars (names, dataset order),
//   stages: {load, odometry, initialization, calibration, shock}: seconds per frame {mean, p50, p95, max},
//   total_seconds (the four estimator stages, load excluded), lost_frames, trusted_set_changes,
//   calibration_frames (frames in online-calibration mode),
//   per_frame: [{stamp, mode ("calibration" | "odometry"), lost, trusted_changed,
//                lidars: {NAME: {role, scan_missing, lambda_min (null: no window), accepted,
//                                window_estimate ({translation, quaternion_wxyz} or null),
//                                window_information, window_residual_variance_m2, window_step_m,
//                                window_step_deg (the last re-matching pass's change), window_settled,
//                                mean_residual_m (null: none), shock, reinitialized}},
//                seconds: {load, odometry, initialization, calibration, shock, window}}],
//   convergence: {lambda_calib, accepted_needed} (Algorithm 1's thresholds, from the config; slam_job),
//   per_lidar: {NAME: {role, translation, quaternion_wxyz, covariance (36 or null),
//               initialization: {state, frame (null), pairs_stored, pairs_seen, singular_values,
//                                translation_eigenvalues, rotation_rms_rad, planar_motion, unobservable_axis_base},
//               converged_frame (null), first_converged_frame (null), accepted, outlier_windows, restarts, shock_frames, missing_frames,
//               weak_directions: [{description, eigenvalue}]}}
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "mlidar/pipelines/slam_estimator.hpp"

namespace mlidar::pipelines {

/// `order[e]`: the dataset index of the estimator's LiDAR e (frames are in
/// estimator order); `lidars` in dataset order; `load_seconds` per frame.
nlohmann::json slam_metrics_json(const std::vector<SlamFrame>& frames, const std::vector<std::size_t>& order,
                                 const std::vector<SlamLidarReport>& lidars, const std::vector<double>& load_seconds,
                                 std::string_view calibrate);

}  // namespace mlidar::pipelines
