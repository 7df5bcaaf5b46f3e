#pragma once
// Refinement of PS-Calib (thesis eq 2.8): robust point-to-plane least squares
// over the points of BOTH clouds. The thesis measures target points against
// the reference planes and reference points against the target planes, with
// the planes held fixed; we estimate the three planes (in the reference
// frame) jointly with T_ref_target, which uses the same residuals in both
// directions but makes them independent, so the covariance of T is honest:
//   reference point p on plane i:  r = n_i . p + d_i
//   target point q on plane i:     r = n_i . (R q + t) + d_i
// Huber loss (IRLS weights), Levenberg-Marquardt with analytic Jacobians,
// 15 parameters: [dt, dr] of T (t + dt, R Exp(dr)) and per plane a 2D normal
// tangent plus an offset step.
#include <array>
#include <vector>

#include "mlidar/calib/planes_types.hpp"

namespace mlidar::calib {

struct RefineProblem {
  std::array<std::vector<Vec3>, 3> ref_points;     ///< per plane, reference frame
  std::array<std::vector<Vec3>, 3> target_points;  ///< per plane, target frame
  std::array<Plane, 3> planes_ref;                 ///< initial planes, reference frame
  SE3 T_ref_target;                                ///< initial guess
};

struct RefineOptions {
  double huber_delta = 0.1;
  int max_iterations = 1000;
};

struct RefineResult {
  SE3 T_ref_target;
  std::array<Plane, 3> planes_ref;
  Mat6 covariance = Mat6::Zero();      ///< of [dt, dr], marginal over the planes, scaled by residual_sigma^2
  double residual_sigma = 0.0;         ///< sqrt(sum w r^2 / (m - 15))
  std::array<double, 3> rms_ref{};     ///< per plane, reference points
  std::array<double, 3> rms_target{};  ///< per plane, target points
  int iterations = 0;
  bool converged = false;
};

/// Precondition: at least 6 points per plane and cloud (callers check).
RefineResult refine_planes(const RefineProblem& problem, const RefineOptions& options);

}  // namespace mlidar::calib
