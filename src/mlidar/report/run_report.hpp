#pragma once
// report.html of a run folder: one self-contained page (inline SVG and CSS,
// nothing fetched) with the sections the folder has data for: a summary with
// verdicts and warnings in words, the trajectory (top and side views with
// equal axes; ground truth and the error over time when the dataset has
// them), per LiDAR the online calibration (lambda_min per window against
// lambda_calib, the window estimates with +-2 sigma bands, the final
// extrinsic with its 1-sigma and weak directions, the error and NEES against
// ground truth), and the time per stage. Written by the jobs at the end of a
// run and again by `mlidar report RUN`.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "mlidar/core/types.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/pose_covariance_io.hpp"

namespace mlidar::report {

/// What a run folder holds, read for the report.
struct RunData {
  std::filesystem::path folder;
  std::string title_folder;  ///< the folder's name as the title shows it
  std::string command;       ///< "slam", "calibrate auto", "odometry", ...
  std::string dataset;       ///< as given to the job; empty when unknown
  nlohmann::json run_info;   ///< run.json (null before the run is committed)
  nlohmann::json metrics;    ///< metrics.json, calibration.json or eval.json (null when absent)
  std::optional<Trajectory> trajectory;
  std::vector<io::StampedCovariance> pose_covariances;  ///< pose_covariance.txt (empty when absent)
  std::optional<io::Extrinsics> extrinsics;
  std::vector<Eigen::Vector3f> map;             ///< map.ply's points (empty when absent)
  std::vector<float> map_traces;                ///< tr(Sigma) of each map point when map.ply carries covariances, else empty
  std::vector<std::uint8_t> map_lidars;         ///< each map point's LiDAR (index into metrics.json "lidars") when map.ply says, else empty
  std::optional<Trajectory> gt_trajectory;      ///< FOLDER/groundtruth.tum (eval traj), else DATASET/groundtruth/trajectory.tum
  std::optional<io::Extrinsics> gt_extrinsics;  ///< DATASET/groundtruth/extrinsics.yaml
  std::vector<std::string> notes;               ///< what could not be read, in words
};

/// What a report is made from besides the folder; each empty field defaults.
struct ReportSource {
  std::string command;                 ///< default: run.json's (a job writes its report before run.json exists)
  std::filesystem::path dataset;       ///< default: run.json's --dataset argument, when it is still there
  std::filesystem::path shown_folder;  ///< the folder's name in the title (a job's staging folder is renamed later)
};

/// Reads `folder`. InputError (exit 3) naming the file when it is no run
/// folder (no run.json and no command given) or its JSON cannot be read.
RunData load_run(const std::filesystem::path& folder, const ReportSource& source = {});

/// The page. The same RunData gives the same bytes.
std::string render_report_html(const RunData& run);

/// load_run + render_report_html written atomically to FOLDER/report.html.
void write_run_report(const std::filesystem::path& folder, const ReportSource& source);

}  // namespace mlidar::report
