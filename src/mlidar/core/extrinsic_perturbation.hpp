#pragma once
// Extrinsic perturbation and the uncertainty it puts on points (thesis 6.4.1).
// An extrinsic T = (R, t) is perturbed as t = rho + t_bar (eq 6.1) and
// R = Exp(phi) R_bar (eq 6.2, phi in the base frame); a point p = zeta + p_bar
// (eq 6.3). Its base-frame position y = R p + t has, to first order, the
// covariance Xi = H Theta H^T, H = [I, -(R_bar p_bar)^, R_bar] (eq 6.5-6.7),
// Theta = diag(P, Phi, Z). The prior of eq 6.8 is P = (1/20 m)^2 I,
// Phi = (1/10 rad)^2 I, Z = (1/50 m)^2 I, the first six entries scaled by alpha.
//
// The propagation is core/pose_uncertainty's point_covariance (the one used by
// uncertainty-aware mapping, eq 4.25-4.29): (rho, phi) is turned into that
// function's left perturbation Exp(d) T_bar, d = [rho + t_bar^ phi, phi],
// which gives eq 6.6's H exactly. Note: the matrix the thesis prints in eq 6.9
// is what H = [I, -(R_bar p_bar + t_bar)^, R_bar] gives (rho, phi taken as
// that left perturbation); eq 6.6 as written gives a smaller one for a LiDAR
// away from the base origin (tests/core/test_extrinsic_perturbation.cpp).
#include <random>

#include "mlidar/core/pose_uncertainty.hpp"

namespace mlidar {

/// Eq 6.8's prior with its scale alpha (alpha multiplies the variances of rho and phi, not of zeta).
struct PerturbationPrior {
  double alpha = 0.0;
  double translation_sigma_m = 1.0 / 20.0;
  double rotation_sigma_rad = 1.0 / 10.0;
  double point_sigma_m = 1.0 / 50.0;

  double scaled_translation_sigma() const;  ///< sqrt(alpha) * translation_sigma_m
  double scaled_rotation_sigma() const;     ///< sqrt(alpha) * rotation_sigma_rad
};

/// diag(alpha P, alpha Phi) in [rho, phi] order: eq 6.1-6.2's tangent (translation added, rotation on the left).
Mat6 perturbation_covariance(const PerturbationPrior& prior);

/// The same covariance in extrinsics.yaml's [t additive, r local] tangent at T_base_lidar (rotation R^T Phi R).
Mat6 perturbation_covariance_in_file_tangent(const PerturbationPrior& prior, const SE3& T_base_lidar);

/// The covariance (rho, phi) as core's left perturbation Exp(d) T_bar: d = J [rho, phi], J = [I, t_bar^; 0, I].
Mat6 perturbation_as_left_covariance(const Mat6& rho_phi_covariance, const SE3& T_base_lidar);

/// T_base_lidar with the prior as core's left-perturbation covariance, for point_covariance (one per LiDAR).
UncertainPose uncertain_extrinsic(const SE3& T_base_lidar, const PerturbationPrior& prior);

/// Z of eq 6.8: point_sigma_m^2 I (m^2, LiDAR frame).
Mat3 prior_point_noise(const PerturbationPrior& prior);

/// A perturbed extrinsic (eq 6.1-6.2): each of the six components of (rho, phi) drawn from N(0, sigma^2) and
/// bounded at sigma (6.6.1.3: drawn again until |x| <= sigma, which removes outliers).
SE3 sample_perturbed_extrinsic(const SE3& T_base_lidar, const PerturbationPrior& prior, std::mt19937_64& rng);

/// Xi (m^2, base frame) of eq 6.7 for point p_lidar of a LiDAR at T_base_lidar under the prior.
Mat3 perturbed_point_covariance(const SE3& T_base_lidar, const PerturbationPrior& prior, const Vec3& p_lidar);

}  // namespace mlidar
