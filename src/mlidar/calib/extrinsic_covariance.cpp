#include "mlidar/calib/extrinsic_covariance.hpp"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "mlidar/core/covariance.hpp"

namespace mlidar::calib {
namespace {

/// Mean over the components with non-zero variance of the lag-k autocorrelation (divisor n at every lag).
double mean_autocorrelation(std::span<const Vec6> x, std::size_t lag, const Vec6& variance) {
  const std::size_t n = x.size();
  double sum = 0.0;
  int components = 0;
  for (int c = 0; c < 6; ++c) {
    if (!(variance(c) > 0.0)) continue;
    double covariance = 0.0;
    for (std::size_t i = 0; i + lag < n; ++i) covariance += x[i](c) * x[i + lag](c);
    sum += covariance / static_cast<double>(n) / variance(c);
    ++components;
  }
  return components > 0 ? sum / components : 0.0;
}

Mat6 pseudo_inverse(const Mat6& A) {
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(0.5 * (A + A.transpose()));
  const double cutoff = 1e-12 * std::max(eig.eigenvalues().cwiseAbs().maxCoeff(), 0.0);
  Vec6 inverse = Vec6::Zero();
  for (int k = 0; k < 6; ++k)
    if (eig.eigenvalues()(k) > cutoff && eig.eigenvalues()(k) > 0.0) inverse(k) = 1.0 / eig.eigenvalues()(k);
  return eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

double integrated_autocorrelation_time(std::span<const Vec6> deviations) {
  const std::size_t n = deviations.size();
  if (n < 3) return 1.0;
  Vec6 variance = Vec6::Zero();
  for (const Vec6& d : deviations) variance += d.cwiseProduct(d);
  variance /= static_cast<double>(n);
  if (!(variance.maxCoeff() > 0.0)) return 1.0;
  // tau = -1 + 2 sum_m Gamma_m, Gamma_m = rho_2m + rho_2m+1 (rho_0 = 1), while Gamma_m > 0.
  double tau = -1.0;
  for (std::size_t m = 0; 2 * m + 1 < n; ++m) {
    const double gamma = mean_autocorrelation(deviations, 2 * m, variance) + mean_autocorrelation(deviations, 2 * m + 1, variance);
    if (!(gamma > 0.0)) break;
    tau += 2.0 * gamma;
  }
  return std::clamp(tau, 1.0, static_cast<double>(n));
}

Mat6 local_covariance_from_left_information(const SE3& T, const Mat6& information, double residual_variance) {
  return covariance_in_local_tangent(T, residual_variance * pseudo_inverse(information));
}

CalibrationCovariance calibration_covariance(std::span<const Vec6> deviations, std::span<const Mat6> window_covariances, double min_tau) {
  const std::size_t n = deviations.size();
  if (n < 2) throw std::invalid_argument("calibration_covariance: needs at least 2 estimates");
  if (!window_covariances.empty() && window_covariances.size() != n)
    throw std::invalid_argument("calibration_covariance: one window covariance per estimate (or none) expected");
  CalibrationCovariance result;
  result.autocorrelation_time = std::clamp(std::max(integrated_autocorrelation_time(deviations), min_tau), 1.0, static_cast<double>(n));
  Mat6 sample = Mat6::Zero();
  for (const Vec6& d : deviations) sample += d * d.transpose();
  sample /= static_cast<double>(n - 1);
  result.spread = sample * (result.autocorrelation_time / static_cast<double>(n));
  for (const Mat6& C : window_covariances) result.windows += C / static_cast<double>(n);
  result.total = result.spread + result.windows;
  return result;
}

}  // namespace mlidar::calib
