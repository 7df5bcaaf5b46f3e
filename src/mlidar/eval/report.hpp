#pragma once
// JSON and text renderings of the evaluation results. The JSON key names are
// a public interface (the README lists them); add keys, never rename them.
// NaN (no value, e.g. no RPE pair) is written as null.
//
// mlidar eval traj:
//   {"gt_poses", "est_poses", "matched_poses",
//    "alignment": {"mode": "none|origin|se3|sim3", "scale", "translation": [x,y,z], "quaternion_wxyz": [w,x,y,z]},
//    "ate": {"translation_m": STATS, "rotation_deg": STATS},
//    "rpe": {"delta", "delta_unit": "frames|m", "translation_m": STATS, "translation_percent": STATS,
//            "rotation_deg": STATS},
//    "kitti": null | {"segments", "translation_percent", "rotation_deg_per_100m",
//                     "by_length": [{"length_m", "segments", "translation_percent", "rotation_deg_per_100m"}]}}
//   STATS = {"count", "rmse", "mean", "median", "std", "min", "max"}
//   with --covariance: "pose_nees": {"skipped", "pose": BAND, "translation": BAND, "stamps": [...], "values": [...]}
//   BAND = {"frames", "median", "inside", "below", "above", "band_95": [low, high]} (shares in [0, 1])
// mlidar eval calib:
//   {"lidars": [{"name", "rotation_error_deg", "translation_error_m",
//                "nees": null | number, "nees_bound_95": 12.59..., "nees_within_95": null | bool}]}
// mlidar eval map:
//   {"points", "points_used", "radius_m", "min_neighbors", "mean_map_entropy", "mean_plane_variance"}
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mlidar/eval/calibration_metrics.hpp"
#include "mlidar/eval/map_metrics.hpp"
#include "mlidar/eval/pose_nees.hpp"
#include "mlidar/eval/surface_error.hpp"
#include "mlidar/eval/trajectory_metrics.hpp"

namespace mlidar::eval {

nlohmann::json to_json(const ErrorStats& stats);
nlohmann::json to_json(const TrajectoryReport& report);
nlohmann::json to_json(const std::vector<ExtrinsicError>& errors);
nlohmann::json to_json(const MapMetrics& metrics, const MapMetricsOptions& options);
nlohmann::json to_json(const PoseNees& nees);

/// Short human-readable tables (a few lines each).
std::string format_table(const TrajectoryReport& report);
std::string format_table(const std::vector<ExtrinsicError>& errors);
std::string format_table(const MapMetrics& metrics, const MapMetricsOptions& options);
/// `eval map --gt-surfaces`: JSON `{points, matched, max_distance_m, distance_m {stats}, normalized_error {points, mean,
/// variance, inside_95} | null}` and its table lines.
nlohmann::json to_json(const SurfaceError& error, const SurfaceErrorOptions& options);
std::string format_table(const SurfaceError& error, const SurfaceErrorOptions& options);
std::string format_table(const PoseNees& nees);

}  // namespace mlidar::eval
