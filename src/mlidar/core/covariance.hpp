#pragma once
// Small summaries of covariance matrices used by the calibrations' verdicts.
#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "mlidar/core/se3.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar {

/// The largest 1-sigma of a 3x3 covariance block: sqrt of its largest eigenvalue (0 for a negative one).
inline double largest_sd(const Mat3& block) {
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Mat3>(block).eigenvalues()(2)));
}

/// M with e = M d: a left perturbation Exp(d) T, d = [rho, phi] (world frame), in the [t additive, r local]
/// tangent of extrinsics.yaml and pose_covariance.txt, T = (R Exp(r), t + dt), to first order:
/// Exp(d) T ~ (R Exp(R^T phi), t + rho - [t]x phi), so M = [I, -[t]x; 0, R^T]. Covariances map as M C M^T.
inline Mat6 left_to_local_tangent(const SE3& T) {
  Mat6 M = Mat6::Zero();
  M.topLeftCorner<3, 3>().setIdentity();
  M.topRightCorner<3, 3>() = -hat(T.translation());
  M.bottomRightCorner<3, 3>() = T.rotation_matrix().transpose();
  return M;
}

/// A left-perturbation covariance at T (world frame) in the [t additive, r local] tangent: M C M^T.
inline Mat6 covariance_in_local_tangent(const SE3& T, const Mat6& left_covariance) {
  const Mat6 M = left_to_local_tangent(T);
  return M * left_covariance * M.transpose();
}

/// The inverse of left_to_local_tangent: M^-1 = [I, [t]x R; 0, R], d = M^-1 e.
inline Mat6 local_to_left_tangent(const SE3& T) {
  const Mat3 R = T.rotation_matrix();
  Mat6 M = Mat6::Zero();
  M.topLeftCorner<3, 3>().setIdentity();
  M.topRightCorner<3, 3>() = hat(T.translation()) * R;
  M.bottomRightCorner<3, 3>() = R;
  return M;
}

/// A [t additive, r local] covariance at T (extrinsics.yaml's) as a left perturbation (world / base frame).
inline Mat6 covariance_in_left_tangent(const SE3& T, const Mat6& local_covariance) {
  const Mat6 M = local_to_left_tangent(T);
  return M * local_covariance * M.transpose();
}

/// The 1-sigma of each axis of a covariance (0 for a negative diagonal entry).
inline Vec6 axis_sigmas(const Mat6& covariance) { return covariance.diagonal().cwiseMax(0.0).cwiseSqrt(); }

}  // namespace mlidar
