#pragma once
// `eval traj` on files: reads a ground truth and an estimate (TUM, or KITTI
// pose rows associated by index), evaluates them (trajectory_metrics.hpp) and,
// given the estimate's pose_covariance.txt, the poses' NEES (pose_nees.hpp).
// The CLI and the Python module both call this; the JSON is eval.json's.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "mlidar/eval/pose_nees.hpp"
#include "mlidar/eval/trajectory_metrics.hpp"

namespace mlidar::eval {

struct TrajectoryFiles {
  std::filesystem::path gt;
  std::filesystem::path est;
  std::string format;                ///< "tum" or "kitti"; empty: KITTI when the ground truth ends in .kitti
  std::filesystem::path covariance;  ///< RUN/pose_covariance.txt of the estimate, or empty
};

struct TrajectoryFileEvaluation {
  TrajectoryReport report;
  std::optional<PoseNees> nees;  ///< with TrajectoryFiles::covariance
  nlohmann::json json;           ///< to_json(report), and "pose_nees"
};

/// "none", "origin", "se3", "sim3" -> the mode; UsageError otherwise.
AlignMode parse_align_mode(const std::string& name);

/// `options.associate_by_index` follows the format. InputError naming the file for a bad one.
TrajectoryFileEvaluation evaluate_trajectory_files(const TrajectoryFiles& files, TrajectoryEvalOptions options);

}  // namespace mlidar::eval
