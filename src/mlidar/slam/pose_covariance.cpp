#include "mlidar/slam/pose_covariance.hpp"

#include <cmath>

#include <Eigen/Cholesky>

namespace mlidar::slam {
namespace {

Mat6 prior_information(const MotionPriorSigma& prior) {
  Vec6 diagonal;
  diagonal << Vec3::Constant(1.0 / (prior.translation_m * prior.translation_m)),
      Vec3::Constant(1.0 / (prior.rotation_rad * prior.rotation_rad));
  return diagonal.asDiagonal();
}

}  // namespace

double registration_residual_variance(const RegistrationResult& registration) {
  double sum = 0.0;
  std::size_t matches = 0;
  for (const float r : registration.residuals_m) {
    if (!std::isfinite(r)) continue;
    sum += static_cast<double>(r) * static_cast<double>(r);
    ++matches;
  }
  return matches > 6 ? sum / static_cast<double>(matches - 6) : 0.0;
}

Mat6 registration_covariance(const Mat6& hessian, double residual_variance, const Vec3& held_translation, const MotionPriorSigma& prior) {
  Mat6 information = prior_information(prior);
  Mat6 P = Mat6::Identity();
  if (held_translation.squaredNorm() > 0.0)
    P.topLeftCorner<3, 3>() -= held_translation.normalized() * held_translation.normalized().transpose();
  if (residual_variance > 0.0) information += P * hessian * P / residual_variance;  // sec 4.8.1: Xi = Lambda^-1
  const Mat6 covariance = information.ldlt().solve(Mat6::Identity());
  return 0.5 * (covariance + covariance.transpose());
}

Mat6 registration_covariance(const RegistrationResult& registration, const MotionPriorSigma& prior) {
  return registration_covariance(registration.hessian, registration_residual_variance(registration), registration.weak_translation, prior);
}

const Mat6& PoseCovarianceChain::add(const FrameResult& frame, bool first) {
  if (first) {
    covariance_.setZero();
    held_frames_ = lost_frames_ = 0;
    return covariance_;
  }
  const Mat6 prediction = prior_information(prior_).inverse();
  if (frame.lost()) {
    ++lost_frames_;
    covariance_ += static_cast<double>(2 * lost_frames_ - 1) * prediction;
    return covariance_;
  }
  lost_frames_ = 0;
  const RegistrationResult& registration = frame.registration;
  covariance_ += registration_covariance(registration, prior_);
  if (frame.suspect()) covariance_ += prediction;
  const Vec3& held = registration.weak_translation;
  if (registration.degenerate && held.squaredNorm() > 0.0) {
    // The persisting velocity error: (2n - 1) sigma_t^2 in all, of which the registration's own term gave one.
    ++held_frames_;
    const Vec3 w = held.normalized();
    const Mat3 cone = w * w.transpose() + kHeldDirectionSigmaRad * kHeldDirectionSigmaRad * (Mat3::Identity() - w * w.transpose());
    covariance_.topLeftCorner<3, 3>() += static_cast<double>(2 * held_frames_ - 2) * prior_.translation_m * prior_.translation_m * cone;
  } else {
    held_frames_ = 0;
  }
  return covariance_;
}

}  // namespace mlidar::slam
