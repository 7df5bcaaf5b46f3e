#pragma once
// `mlidar calibrate auto` (thesis Chap. 3, stage "handeye"): every LiDAR's own
// odometry over a dataset folder (slam::Odometry with that LiDAR alone),
// motion pairs A_k = T_{a_{k-s} a_k}, B_k = T_{b_{k-s} b_k} between frames s
// apart, hand-eye per auxiliary LiDAR against the base (calib/hand_eye.hpp),
// and under planar motion the height from the ground planes
// (calib/ground_height.hpp). Writes, each file atomically:
//   RUN/extrinsics.yaml     every LiDAR (base identity), with covariance
//   RUN/calibration.json    per LiDAR: pairs used / rejected, singular values,
//                           verdict, estimate, covariance, ground step
// The result does not depend on the order the dataset lists its LiDARs.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/calib/ground_height.hpp"
#include "mlidar/calib/hand_eye.hpp"

namespace mlidar::pipelines {

struct AutoCalibJob {
  std::filesystem::path dataset;
  std::string base;               ///< empty: the dataset's base, else its first LiDAR
  std::string stage = "handeye";  ///< only "handeye" for now
  int pair_stride = 5;            ///< frames between the two ends of a motion pair
  int ground_frames = 10;         ///< frames (evenly spaced) used for the ground planes
  calib::HandEyeConfig hand_eye;
  calib::GroundHeightConfig ground;
  std::filesystem::path out;
};

struct LidarCalibration {
  std::string name;
  SE3 T_base_lidar;
  Mat6 covariance = Mat6::Zero();
  calib::HandEyeResult hand_eye;                  ///< empty for the base
  std::optional<calib::GroundHeightResult> ground;  ///< run under planar motion
  std::size_t odometry_lost_frames = 0;
  bool usable = true;  ///< false: degenerate / too few pairs / planar without a ground
};

struct AutoCalibSummary {
  std::string base;
  std::vector<LidarCalibration> lidars;  ///< dataset order
  double seconds = 0.0;
  bool all_usable() const;
};

/// UsageError for bad options (unknown base, stage, stride < 1); InputError for bad files.
AutoCalibSummary run_autocalib_job(const AutoCalibJob& job,
                                   const std::function<void(const std::string&, int, int)>& progress = {});

}  // namespace mlidar::pipelines
