#pragma once
// The covariance of Algorithm 1's output (thesis Sec. 4.7.4: the mean of
// L_calib accepted window estimates, covariance alpha Xi_calib), made honest
// about two things the plain sample covariance of the estimates ignores:
//   - consecutive windows share N of their N + 1 frames (and the map), so the
//     accepted estimates are strongly autocorrelated: the variance of their
//     mean is S tau / n, with tau = 1 + 2 sum_k rho_k the integrated
//     autocorrelation time, not S / n (tau ~ N + 1 for overlapping windows);
//   - the windows' own information: each window's estimate has covariance
//     sigma^2 Lambda^-1 (Lambda = J^T J of eq 4.21, sigma^2 the residual
//     variance), and the mean of L_calib overlapping windows is no better
//     than one window's (they reuse the same frames and map points).
// Xi_calib = S tau / n + mean_i sigma_i^2 Lambda_i^-1, where neither term can
// be small unless both the scatter and the geometry say so.
// Tangent: [t, r] with t additive and r local, T = (R Exp(r), t + dt): the
// convention of extrinsics.yaml's covariance (io/extrinsics_io.hpp) and of
// `mlidar eval calib`'s NEES.
#include <span>

#include "mlidar/core/se3.hpp"

namespace mlidar::calib {

/// Integrated autocorrelation time of a sequence of 6-vectors (deviations
/// from their mean), from the mean over the components of the normalised
/// autocorrelation rho_k (biased estimator, divisor n), summed with Geyer's
/// initial positive sequence (pairs rho_2m + rho_2m+1 while positive; Geyer,
/// Statistical Science 7(4), 1992). Clamped to [1, n]; 1 for n < 3 or a
/// constant sequence.
double integrated_autocorrelation_time(std::span<const Vec6> deviations);

/// Covariance of an estimate given as sigma^2 information^-1 for a left
/// perturbation T <- Exp(d) T (the window solver's), in the [t additive, r
/// local] tangent at T: e = M d, M = [I, -[t]x; 0, R^T].
/// information is pseudo-inverted (a direction it does not observe reads 0).
Mat6 local_covariance_from_left_information(const SE3& T, const Mat6& information, double residual_variance);

struct CalibrationCovariance {
  Mat6 total = Mat6::Zero();          ///< spread + windows + bias
  Mat6 spread = Mat6::Zero();         ///< S tau / n
  Mat6 windows = Mat6::Zero();        ///< mean of the windows' own covariances
  Mat6 bias = Mat6::Zero();           ///< shared-error floor (ConvergenceConfig::bias_*), added by the monitor
  double autocorrelation_time = 1.0;  ///< tau used (>= min_tau)
};

/// `deviations`: each accepted estimate's [t_i - t_mean, Log(R_mean^-1 R_i)];
/// `window_covariances`: each one's own covariance (same tangent), empty if
/// unknown. tau is at least `min_tau` (e.g. N + 1: the overlap of consecutive
/// windows makes rho_k >= (N + 1 - k) / (N + 1) for shared-frame noise).
/// Throws std::invalid_argument for fewer than 2 deviations or a size mismatch.
CalibrationCovariance calibration_covariance(std::span<const Vec6> deviations, std::span<const Mat6> window_covariances, double min_tau);

}  // namespace mlidar::calib
