#pragma once
// `mlidar calibrate planes` as a job: PS-Calib (thesis Chap. 2) from one cloud
// of each LiDAR looking at a wall corner, with an optional rough guess
// (extrinsics YAML naming both LiDARs) and planes.yaml. The CLI and the Python
// module both run it; the JSON is `--report`'s.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "mlidar/calib/planes_types.hpp"
#include "mlidar/core/types.hpp"
#include "mlidar/io/extrinsics_io.hpp"

namespace mlidar::pipelines {

struct PlanesJob {
  std::filesystem::path ref;     ///< the reference LiDAR's cloud (PCD, PLY, KITTI .bin)
  std::filesystem::path target;  ///< the target LiDAR's cloud
  std::filesystem::path init;    ///< rough extrinsics naming both (or with the reference as base); empty: none
  std::filesystem::path config;  ///< planes.yaml; empty: the defaults
};

struct PlanesJobResult {
  std::string ref_name;  ///< the clouds' file stems ("ref", "target" when they have none or the same one)
  std::string target_name;
  Scan ref;
  Scan target;
  std::optional<SE3> guess;  ///< T_ref_target from `init`
  calib::PlanesResult result;
  double seconds = 0.0;  ///< the calibration alone
};

/// InputError naming the file for a bad cloud, guess or config.
PlanesJobResult run_planes_job(const PlanesJob& job);

/// extrinsics.yaml of the pair: the reference as base, the target with T_ref_target and its covariance.
io::Extrinsics planes_extrinsics(const PlanesJobResult& job);

/// `--report`'s JSON: verdict, warnings, T_ref_target (and the closed form's), covariance, residuals, planes.
nlohmann::json planes_report_json(const PlanesJobResult& job);

}  // namespace mlidar::pipelines
