#pragma once
// The page of a one-pair calibration (`calibrate planes` and `calibrate
// refine` with --html FILE): the verdict in words, the extrinsic before and
// after with its 1-sigma, and the two clouds overlaid in the reference
// LiDAR's frame before (the guess) and after (the result), seen from above
// and from the side, cells coloured by which cloud has points in them. One
// self-contained page like report.html (run_report.hpp).
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/types.hpp"

namespace mlidar::report {

struct PairCalibration {
  std::string command;  ///< "calibrate planes", "calibrate refine"
  std::string ref_name, target_name;
  std::string ref_file, target_file;
  std::vector<Eigen::Vector3f> ref_points;                 ///< in the reference LiDAR's frame
  std::vector<Eigen::Vector3f> target_points;              ///< in the target LiDAR's frame
  SE3 T_ref_target_before;                                 ///< the guess the solver started from
  std::string before_words;                                ///< where that guess came from, e.g. "the --init guess"
  SE3 T_ref_target;                                        ///< the result
  std::optional<Mat6> covariance;                          ///< of the result, [t, r] (rotation in the local tangent)
  std::string verdict_level = "ok";                        ///< "ok", "warn" or "bad"
  std::string verdict;                                     ///< in words
  std::vector<std::string> reasons;                        ///< warnings and reasons, in words
  std::vector<std::pair<std::string, std::string>> facts;  ///< (what, value) rows: residual, overlap, time, ...
};

/// The page. The same input gives the same bytes.
std::string render_pair_calibration_html(const PairCalibration& pair);

}  // namespace mlidar::report
