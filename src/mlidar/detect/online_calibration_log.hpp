#pragma once
// What online calibration (online_extrinsics.hpp) did over a detection run, per LiDAR: how many registrations ran
// and were trusted, how far they moved the extrinsic, and, when the truth is known (perturbations injected about the
// dataset's own extrinsics), the extrinsic's error before and after. `detect run` writes it to metrics.json.
#include <cstddef>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"
#include "mlidar/detect/detection_frames.hpp"

namespace mlidar::detect {

struct LidarRefineRecord {
  std::string lidar;
  std::size_t registrations = 0;
  std::size_t trusted = 0;
  std::vector<double> rotation_change_deg, translation_change_m;  ///< given -> used, trusted registrations
  std::vector<double> rotation_error_given_deg, rotation_error_used_deg;  ///< against the truth, every registration
  std::vector<double> translation_error_given_m, translation_error_used_m;
};

class OnlineCalibrationLog {
 public:
  /// `truth`: the true extrinsic per LiDAR (dataset order), or empty when unknown.
  OnlineCalibrationLog(const std::vector<std::string>& lidar_names, std::vector<SE3> truth);
  /// A frame as DetectionDataset::read gives it (every LiDAR, dataset order).
  void add(const DetectionFrame& frame);
  const std::vector<LidarRefineRecord>& records() const { return records_; }
  bool knows_truth() const { return !truth_.empty(); }
  std::size_t registrations() const;
  std::size_t untrusted() const;

 private:
  std::vector<LidarRefineRecord> records_;
  std::vector<SE3> truth_;
};

}  // namespace mlidar::detect
