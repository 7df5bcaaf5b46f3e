#pragma once
// Extrinsic calibration error against ground truth: thesis eq 4.31 (EGT) and,
// when the estimate carries a covariance, the normalised estimation error
// squared (Bar-Shalom, Estimation with Applications to Tracking, sec 5.4.2).
#include <optional>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"
#include "mlidar/io/extrinsics_io.hpp"

namespace mlidar::eval {

/// 95 % quantile of the chi-square distribution with 6 degrees of freedom.
inline constexpr double kChiSquare6Dof95 = 12.591587243743977;

struct ExtrinsicError {
  std::string name;
  double rotation_error_deg = 0.0;   ///< |Log(R_gt R_est^-1)| (eq 4.31)
  double translation_error_m = 0.0;  ///< |t_gt - t_est| (eq 4.31)
  std::optional<double> nees;        ///< set when a positive-definite covariance is given
  bool nees_within_95() const { return nees.has_value() && *nees <= kChiSquare6Dof95; }
};

/// Error of one extrinsic. The NEES uses the error in the covariance's
/// [t, r] tangent: t_gt = t_est + e_t, R_gt = R_est Exp(e_r), NEES = e^T Sigma^-1 e;
/// it stays empty when the covariance is absent or not positive definite.
ExtrinsicError extrinsic_error(const SE3& T_base_lidar_gt, const SE3& T_base_lidar_est, const std::optional<Mat6>& covariance_est);

/// One entry per LiDAR of `gt`, in its order. Throws InputError(est_source,
/// "lidars.NAME", ...) when the estimate lacks a LiDAR of the ground truth.
std::vector<ExtrinsicError> evaluate_calibration(const io::Extrinsics& gt, const io::Extrinsics& est, const std::string& est_source);

}  // namespace mlidar::eval
