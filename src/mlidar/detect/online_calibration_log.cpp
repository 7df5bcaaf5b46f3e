#include "mlidar/detect/online_calibration_log.hpp"

#include "mlidar/eval/calibration_metrics.hpp"

namespace mlidar::detect {

OnlineCalibrationLog::OnlineCalibrationLog(const std::vector<std::string>& lidar_names, std::vector<SE3> truth)
    : truth_(std::move(truth)) {
  for (const std::string& name : lidar_names) {
    LidarRefineRecord record;
    record.lidar = name;
    records_.push_back(std::move(record));
  }
}

void OnlineCalibrationLog::add(const DetectionFrame& frame) {
  for (std::size_t j = 0; j < frame.placements.size() && j < records_.size(); ++j) {
    const LidarPlacement& placement = frame.placements[j];
    if (!placement.refine_ran) continue;
    LidarRefineRecord& record = records_[j];
    ++record.registrations;
    if (calib::is_trusted(placement.refine_verdict)) {
      ++record.trusted;
      const eval::ExtrinsicError change = eval::extrinsic_error(placement.T_base_lidar_given, placement.T_base_lidar, std::nullopt);
      record.rotation_change_deg.push_back(change.rotation_error_deg);
      record.translation_change_m.push_back(change.translation_error_m);
    }
    if (truth_.empty()) continue;
    const eval::ExtrinsicError given = eval::extrinsic_error(truth_[j], placement.T_base_lidar_given, std::nullopt);
    const eval::ExtrinsicError used = eval::extrinsic_error(truth_[j], placement.T_base_lidar, std::nullopt);
    record.rotation_error_given_deg.push_back(given.rotation_error_deg);
    record.rotation_error_used_deg.push_back(used.rotation_error_deg);
    record.translation_error_given_m.push_back(given.translation_error_m);
    record.translation_error_used_m.push_back(used.translation_error_m);
  }
}

std::size_t OnlineCalibrationLog::registrations() const {
  std::size_t n = 0;
  for (const LidarRefineRecord& record : records_) n += record.registrations;
  return n;
}

std::size_t OnlineCalibrationLog::untrusted() const {
  std::size_t n = 0;
  for (const LidarRefineRecord& record : records_) n += record.registrations - record.trusted;
  return n;
}

}  // namespace mlidar::detect
