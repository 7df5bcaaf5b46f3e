#include "mlidar/eval/calibration_metrics.hpp"

#include <algorithm>
#include <numbers>

#include <Eigen/Cholesky>

#include "mlidar/core/error.hpp"

namespace mlidar::eval {

ExtrinsicError extrinsic_error(const SE3& T_base_lidar_gt, const SE3& T_base_lidar_est, const std::optional<Mat6>& covariance_est) {
  constexpr double kRadToDeg = 180.0 / std::numbers::pi;
  ExtrinsicError error;
  const Quat& R_gt = T_base_lidar_gt.rotation();
  const Quat& R_est = T_base_lidar_est.rotation();
  error.rotation_error_deg = kRadToDeg * so3_log(R_gt * R_est.conjugate()).norm();
  error.translation_error_m = (T_base_lidar_gt.translation() - T_base_lidar_est.translation()).norm();
  if (covariance_est.has_value()) {
    Vec6 e;
    e << T_base_lidar_gt.translation() - T_base_lidar_est.translation(), so3_log(R_est.conjugate() * R_gt);
    const Eigen::LLT<Mat6> llt(*covariance_est);
    if (llt.info() == Eigen::Success) error.nees = e.dot(llt.solve(e));
  }
  return error;
}

std::vector<ExtrinsicError> evaluate_calibration(const io::Extrinsics& gt, const io::Extrinsics& est, const std::string& est_source) {
  std::vector<ExtrinsicError> errors;
  for (const io::LidarExtrinsic& truth : gt.lidars) {
    const auto estimate =
        std::find_if(est.lidars.begin(), est.lidars.end(), [&](const io::LidarExtrinsic& lidar) { return lidar.name == truth.name; });
    if (estimate == est.lidars.end()) throw InputError(est_source, "lidars." + truth.name, "missing; the ground truth has this LiDAR");
    errors.push_back(extrinsic_error(truth.T_base_lidar, estimate->T_base_lidar, estimate->covariance));
    errors.back().name = truth.name;
  }
  return errors;
}

}  // namespace mlidar::eval
