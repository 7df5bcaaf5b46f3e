#include "mlidar/eval/plane_fit_toy.hpp"

#include <algorithm>
#include <numeric>
#include <random>

#include <Eigen/Cholesky>

#include "mlidar/core/extrinsic_perturbation.hpp"

namespace mlidar::eval {
namespace {

Vec3 noise(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> normal(0.0, sigma);
  Vec3 n;
  for (int k = 0; k < 3; ++k) n(k) = normal(rng);
  return n;
}

/// One trial: e_x of the unweighted and the weighted fit.
std::pair<double, double> trial(const PlaneFitToySpec& spec, const Vec3& x_true, std::mt19937_64& rng) {
  PerturbationPrior prior;
  prior.alpha = spec.alpha;
  prior.point_sigma_m = spec.noise_sigma_m;
  const SE3 T_perturbed = sample_perturbed_extrinsic(spec.T_base_lidar2, prior, rng);
  const UncertainPose lidar2 = uncertain_extrinsic(T_perturbed, prior);
  const Mat3 Z = prior_point_noise(prior);
  const double base_trace = Z.trace();  // the base LiDAR's extrinsic is the identity, exactly: Xi = Z
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Vec3> merged;
  std::vector<double> weights;
  std::vector<int> order(static_cast<std::size_t>(spec.points));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);  // a random half for each LiDAR
  for (const int j : order) {
    const double a = unit(rng), b = unit(rng);
    const Vec3 y_true = spec.patch.centre + a * spec.patch.half_u * spec.patch.u + b * spec.patch.half_v * spec.patch.v;
    if (j % 2 == 0) {
      merged.push_back(y_true + noise(rng, spec.noise_sigma_m));
      weights.push_back(1.0 / base_trace);
    } else {
      const Vec3 p_lidar2 = spec.T_base_lidar2.inverse() * y_true + noise(rng, spec.noise_sigma_m);
      merged.push_back(T_perturbed * p_lidar2);
      weights.push_back(1.0 / point_covariance(lidar2, p_lidar2, Z).trace());
    }
  }
  const std::vector<double> ones(merged.size(), 1.0);
  return {(fit_plane_coefficients(merged, ones) - x_true).norm(), (fit_plane_coefficients(merged, weights) - x_true).norm()};
}

}  // namespace

Vec3 fit_plane_coefficients(std::span<const Vec3> points, std::span<const double> weights) {
  Mat3 AtWA = Mat3::Zero();
  Vec3 AtW1 = Vec3::Zero();
  for (std::size_t j = 0; j < points.size(); ++j) {
    AtWA += weights[j] * points[j] * points[j].transpose();
    AtW1 += weights[j] * points[j];
  }
  return AtWA.ldlt().solve(AtW1);
}

PlaneFitToyResult run_plane_fit_toy(const PlaneFitToySpec& spec) {
  const Vec3 normal = spec.patch.u.cross(spec.patch.v).normalized();
  const Vec3 x_true = normal / normal.dot(spec.patch.centre);  // n^T y = d  <=>  (n / d)^T y = 1
  std::mt19937_64 rng(spec.seed);
  PlaneFitToyResult result;
  for (int t = 0; t < spec.trials; ++t) {
    const auto [unweighted, weighted] = trial(spec, x_true, rng);
    result.errors_unweighted.push_back(unweighted);
    result.errors_weighted.push_back(weighted);
  }
  const auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / std::max<std::size_t>(1, v.size());
  };
  result.mean_error_unweighted = mean(result.errors_unweighted);
  result.mean_error_weighted = mean(result.errors_weighted);
  return result;
}

}  // namespace mlidar::eval
