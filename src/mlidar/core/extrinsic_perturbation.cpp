#include "mlidar/core/extrinsic_perturbation.hpp"

#include <cmath>

#include "mlidar/core/covariance.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar {

double PerturbationPrior::scaled_translation_sigma() const { return std::sqrt(alpha) * translation_sigma_m; }
double PerturbationPrior::scaled_rotation_sigma() const { return std::sqrt(alpha) * rotation_sigma_rad; }

Mat6 perturbation_covariance(const PerturbationPrior& prior) {
  const double translation = prior.scaled_translation_sigma(), rotation = prior.scaled_rotation_sigma();
  Vec6 variances;
  variances << Vec3::Constant(translation * translation), Vec3::Constant(rotation * rotation);
  return variances.asDiagonal();
}

Mat6 perturbation_covariance_in_file_tangent(const PerturbationPrior& prior, const SE3& T_base_lidar) {
  // r_local = R^T phi (R Exp(r_local) = Exp(R r_local) R), the translation is added in both.
  Mat6 covariance = perturbation_covariance(prior);
  const Mat3 R = T_base_lidar.rotation_matrix();
  covariance.bottomRightCorner<3, 3>() = R.transpose() * covariance.bottomRightCorner<3, 3>() * R;
  return covariance;
}

Mat6 perturbation_as_left_covariance(const Mat6& rho_phi_covariance, const SE3& T_base_lidar) {
  // Exp(phi) R_bar, t_bar + rho = Exp(d) T_bar to first order with d = [rho + t_bar^ phi, phi].
  Mat6 J = Mat6::Identity();
  J.topRightCorner<3, 3>() = hat(T_base_lidar.translation());
  return J * rho_phi_covariance * J.transpose();
}

UncertainPose uncertain_extrinsic(const SE3& T_base_lidar, const PerturbationPrior& prior) {
  return {T_base_lidar, perturbation_as_left_covariance(perturbation_covariance(prior), T_base_lidar)};
}

Mat3 prior_point_noise(const PerturbationPrior& prior) { return prior.point_sigma_m * prior.point_sigma_m * Mat3::Identity(); }

SE3 sample_perturbed_extrinsic(const SE3& T_base_lidar, const PerturbationPrior& prior, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  // One standard normal bounded at 1 (6.6.1.3), scaled by sigma.
  const auto bounded = [&](double sigma) {
    double x = normal(rng);
    while (std::abs(x) > 1.0) x = normal(rng);
    return sigma * x;
  };
  Vec3 rho, phi;
  for (int i = 0; i < 3; ++i) rho(i) = bounded(prior.scaled_translation_sigma());
  for (int i = 0; i < 3; ++i) phi(i) = bounded(prior.scaled_rotation_sigma());
  // Eq 6.1-6.2: t = rho + t_bar, R = Exp(phi) R_bar.
  return SE3(so3_exp(phi) * T_base_lidar.rotation(), T_base_lidar.translation() + rho);
}

Mat3 perturbed_point_covariance(const SE3& T_base_lidar, const PerturbationPrior& prior, const Vec3& p_lidar) {
  return point_covariance(uncertain_extrinsic(T_base_lidar, prior), p_lidar, prior_point_noise(prior));
}

}  // namespace mlidar
