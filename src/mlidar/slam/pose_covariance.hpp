#pragma once
// Covariance of each frame's pose T_world_base (thesis sec 4.8.1: Xi = Lambda^-1
// of the registration), and its growth along the run.
//
// One registration against the local map (eq 4.23) gives the information
// H / sigma^2, with H = J^T W J at the solution (robust weights included) and
// sigma^2 the residual variance per row of its matches. Where the geometry
// does not observe a direction (a corridor's axis), the registration keeps
// the motion prior's value there (solution remapping): the information along
// that translation is taken out of H (P H P, P = I - w w^T on the translation
// block, w the held direction) and the prior's is added:
// Xi_reg = (P H P / sigma^2 + Lambda_prior)^-1, Lambda_prior
// = diag(1 / sigma_t^2, 1 / sigma_r^2) per axis, the sigmas being how far a
// constant-velocity prediction may be off in one frame. A lost frame keeps the
// prediction alone: Xi_reg = Lambda_prior^-1; a suspect one (its pose may be
// wrong, issue 18) adds that to its registration's.
//
// A direction held at the prediction frame after frame keeps the same
// velocity error (a corridor: the velocity along the axis is never measured
// again), so its error grows linearly, not as a random walk: the n-th
// consecutive held frame adds (2n - 1) sigma_t^2 along it (the variance after
// n frames is (n sigma_t)^2); likewise for consecutive lost frames. The held
// direction w is the registration's weakest translation, itself uncertain
// (on the simulated corridor it leans 0.01-0.03 rad out of the axis from frame
// to frame), so that variance is spread over a cone of kHeldDirectionSigmaRad
// around w: w w^T + kHeldDirectionSigmaRad^2 (I - w w^T).
//
// The map the frame is registered to was built at the earlier poses and
// carries their error, so the pose covariance accumulates (a random walk):
// Xi_k = Xi_(k-1) + Xi_reg,k, Xi_0 = 0 (the first frame defines the world).
// This is an upper model for a run that keeps exploring; a run that returns
// to mapped places is closer to the map's early frames than it says.
//
// Tangent: left perturbation T = Exp(d) T_mean, d = [t, r] in the world frame
// (the registration's); left_to_local_tangent (core/covariance.hpp) turns it
// into the [t additive, r local] tangent that pose_covariance.txt uses.
#include "mlidar/core/se3.hpp"
#include "mlidar/slam/odometry.hpp"
#include "mlidar/slam/scan_to_map.hpp"

namespace mlidar::slam {

/// Angular 1-sigma of a held translation's direction (see above).
inline constexpr double kHeldDirectionSigmaRad = 0.05;

struct MotionPriorSigma {
  double translation_m = 0.1;  ///< per axis, per frame
  double rotation_rad = 0.05;  ///< per axis, per frame (2.9 deg)
};

/// sigma^2 of the registration's matched residuals: sum |r|^2 / (matches - 6); NaN residuals (no match) are
/// skipped; 0 with 6 matches or fewer.
double registration_residual_variance(const RegistrationResult& registration);

/// Xi_reg = (P H P / sigma^2 + Lambda_prior)^-1; Lambda_prior^-1 alone when sigma^2 is 0 (nothing matched).
/// `held_translation`: the unit translation (world) the registration kept at the prior, zero for none.
Mat6 registration_covariance(const Mat6& hessian, double residual_variance, const Vec3& held_translation, const MotionPriorSigma& prior);
/// The same of one registration: its H, its residual variance and the translation it held.
Mat6 registration_covariance(const RegistrationResult& registration, const MotionPriorSigma& prior);

/// The accumulated covariance, one frame at a time (frames in order).
class PoseCovarianceChain {
 public:
  explicit PoseCovarianceChain(MotionPriorSigma prior = {}) : prior_(prior) {}
  /// Adds one frame (`first`: the run's first, Xi = 0). Returns Xi_k (left perturbation, world frame).
  const Mat6& add(const FrameResult& frame, bool first);

 private:
  MotionPriorSigma prior_;
  Mat6 covariance_ = Mat6::Zero();
  int held_frames_ = 0;  ///< consecutive frames with a translation held at the prediction
  int lost_frames_ = 0;  ///< consecutive lost frames
};

}  // namespace mlidar::slam
