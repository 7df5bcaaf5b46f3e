#pragma once
// `mlidar calibrate auto` (thesis Chap. 3). Stage "handeye": every LiDAR's own
// odometry over a dataset folder (slam::Odometry with that LiDAR alone),
// motion pairs A_k = T_{a_{k-s} a_k}, B_k = T_{b_{k-s} b_k} between frames s
// apart, hand-eye per auxiliary LiDAR against the base (calib/hand_eye.hpp),
// and under planar motion the height from the ground planes
// (calib/ground_height.hpp). Stage "refine": the appearance refinement of
// each auxiliary LiDAR against the base's local maps (autocalib_refine.hpp).
// Stage "all" (the default): hand-eye, then refine from its result.
// Starting extrinsics (--init): required by "refine", refused by "handeye";
// under "all" hand-eye still runs and is reported, and --init is the refine
// start only for LiDARs whose hand-eye result is unusable (degenerate motion,
// planar motion without a ground), so a poor drive can still be refined.
// Writes, each file atomically:
//   RUN/extrinsics.yaml     every LiDAR (base identity), with covariance: the
//                           refined result where refine ran, else hand-eye's
//   RUN/calibration.json    per LiDAR: "handeye" (pairs used / rejected, singular
//                           values, verdict, estimate, ground step), "refine"
//                           (frames tried, overlap ratios, candidate errors, kept,
//                           estimate, covariances, verdict), final estimate
// The result does not depend on the order the dataset lists its LiDARs.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/calib/ground_height.hpp"
#include "mlidar/calib/hand_eye.hpp"
#include "mlidar/pipelines/autocalib_refine.hpp"

namespace mlidar::pipelines {

struct AutoCalibJob {
  std::filesystem::path dataset;
  std::string base;               ///< empty: the dataset's base, else its first LiDAR
  std::string stage = "all";      ///< "handeye", "refine" or "all"
  std::filesystem::path init;     ///< starting extrinsics YAML (empty: none)
  int pair_stride = 5;            ///< frames between the two ends of a motion pair
  int ground_frames = 10;         ///< frames (evenly spaced) used for the ground planes
  int threads = 0;                ///< worker threads (0: all cores)
  calib::HandEyeConfig hand_eye;
  calib::GroundHeightConfig ground;
  RefineConfig refine;
  std::filesystem::path out;
};

struct LidarCalibration {
  std::string name;
  SE3 T_base_lidar;                ///< final: refined where refine ran, else hand-eye's
  Mat6 covariance = Mat6::Zero();
  bool handeye_ran = false;
  SE3 T_base_lidar_handeye;        ///< the hand-eye stage's result (after the ground step)
  Mat6 covariance_handeye = Mat6::Zero();
  calib::HandEyeResult hand_eye;                  ///< empty for the base
  std::string refine_start;                       ///< "handeye" or "init"; empty: refine did not run
  std::optional<RefineResult> refine;
  std::optional<calib::GroundHeightResult> ground;  ///< run under planar motion
  std::size_t odometry_lost_frames = 0;
  /// false: hand-eye unusable and no --init, or refine from --init failed
  /// (a failed refine from hand-eye's result keeps that result, still usable)
  bool usable = true;
};

struct AutoCalibSummary {
  std::string base;
  std::vector<LidarCalibration> lidars;  ///< dataset order
  double seconds = 0.0;
  bool all_usable() const;
};

/// UsageError for bad options (unknown base or stage, stride < 1, --init missing
/// for "refine" or given to "handeye"); InputError for bad files.
AutoCalibSummary run_autocalib_job(const AutoCalibJob& job,
                                   const std::function<void(const std::string&, int, int)>& progress = {});

}  // namespace mlidar::pipelines
