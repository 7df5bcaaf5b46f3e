#pragma once
// Thesis 6.4.3, "covariance prior-enhanced plane fitting": a planar patch seen
// half by the base LiDAR and half by a second LiDAR whose extrinsic is
// perturbed (eq 6.1-6.2, eq 6.8's prior scaled by alpha, bounded at sigma);
// the plane x^T y = 1 (x = n / d for n^T y = d) is fitted to the merged points
// by least squares A x = 1, once unweighted and once with W_jj = 1 / tr(Xi_j)
// (Xi_j of eq 6.7 at the perturbed extrinsic, what a user has). The error of a
// trial is e_x = |x_true - x_est| (Fig 6.2).
#include <cstdint>
#include <span>
#include <vector>

#include "mlidar/core/se3.hpp"

namespace mlidar::eval {

/// A rectangular patch of the plane through `centre` spanned by the unit vectors u and v (half sizes in metres).
struct PlanarPatch {
  Vec3 centre;
  Vec3 u;
  Vec3 v;
  double half_u = 10.0;
  double half_v = 10.0;
};

struct PlaneFitToySpec {
  PlanarPatch patch;
  SE3 T_base_lidar2;   ///< the second LiDAR's true extrinsic (6.4.2: rpy 10 deg, t = (1, 1, 1) m)
  double alpha = 0.0;  ///< eq 6.8's scale
  int points = 10000;  ///< on the patch, split in two halves at random
  double noise_sigma_m = 0.02;
  int trials = 100;
  std::uint64_t seed = 1;
};

struct PlaneFitToyResult {
  double mean_error_unweighted = 0.0;  ///< mean e_x over the trials (1/m)
  double mean_error_weighted = 0.0;
  std::vector<double> errors_unweighted;  ///< per trial
  std::vector<double> errors_weighted;
};

/// x with x^T y = 1 minimising sum_j w_j (x^T y_j - 1)^2: x = (A^T W A)^-1 A^T W 1.
Vec3 fit_plane_coefficients(std::span<const Vec3> points, std::span<const double> weights);

PlaneFitToyResult run_plane_fit_toy(const PlaneFitToySpec& spec);

}  // namespace mlidar::eval
