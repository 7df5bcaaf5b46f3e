#pragma once
// Appearance refinement's arithmetic (thesis 3.4.3.2-3.4.3.3): the overlap
// factor of two scans (eq 3.13-3.14) and the mean of the per-frame extrinsic
// candidates with the smallest registration error, with its covariance.
// Tangent of an extrinsic X = T_base_target here and in every output:
// [e_t, e_r] with t_true = t + e_t, R_true = R Exp(e_r) (as eval::calibration_metrics).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"

namespace mlidar::calib {

/// Eq 3.13-3.14: Omega = |S_a| / |P_a| * |S_b| / |P_b|, where S_a holds the
/// points of a with a point of b within `radius_m` and S_b the points of b
/// with a point of a within it; both clouds in the same frame (b already moved
/// by the initial extrinsic). 0 when either cloud is empty. Non-finite points
/// are dropped first.
double overlap_factor(std::span<const Eigen::Vector3f> points_a, std::span<const Eigen::Vector3f> points_b, double radius_m);

/// One frame's registration of the target LiDAR against the base's local map.
struct ExtrinsicCandidate {
  std::size_t frame = 0;
  SE3 T_base_target;
  double error_m = 0.0;             ///< registration error (mean |point-to-plane residual|)
  Mat6 information = Mat6::Zero();  ///< of T_base_target in the [e_t, e_r] tangent, per m^2 of residual
  /// The registration could not fix the translation along one direction (a street seen by a bumper LiDAR):
  /// that component is the start's, and information says how little it is known.
  bool degenerate = false;
};

/// Information of X = T_world_base^-1 T_world_target in the [e_t, e_r] tangent
/// from a registration's Gauss-Newton matrix H (its left perturbation
/// T_world_target <- Exp(d) T_world_target, [rho, phi]) and residual variance:
/// X <- Exp(Ad(T_world_base^-1) d) X, then e_t = rho' - [t]x phi', e_r = R^T phi'.
Mat6 extrinsic_information(const Mat6& registration_hessian, double residual_variance, const SE3& T_world_base, const SE3& T_base_target);

struct CandidateSelection {
  double keep_fraction = 0.2;  ///< best fraction (by error) kept (thesis: "the minimum registration error")
  std::size_t min_keep = 5;    ///< at least this many kept (all when fewer)
  // Bias shared by every candidate (the base's map and odometry, the ground seen
  // by both LiDARs), invisible in their spread: 1-sigma per axis added to the
  // covariance. Default set on the rhd/handheld and rv/vehicle 300-frame runs
  // (docs/benchmarks.md, "Auto-Calib"): on rhd the five kept candidates agree to
  // 0.6 cm but all 14 sit ~1.2 cm off the truth in z (NEES 28 without the term,
  // 8.7 with it; rv's three LiDARs 1.4-5.6 without, 0.6-1.6 with).
  double bias_translation_sd_m = 0.003;
  double bias_rotation_sd_deg = 0.03;
};

struct CandidateAverage {
  SE3 T_base_target;
  std::vector<std::size_t> kept;  ///< indices into the candidates, best first
  /// Sample covariance of the kept candidates about their mean (not divided by
  /// their count: they are correlated through the base's map and odometry; on
  /// rhd / rv drives the mean's error against the truth is of this size).
  Mat6 covariance_spread = Mat6::Zero();
  Mat6 covariance_icp = Mat6::Zero();   ///< inverse of the summed information of the kept candidates
  Mat6 covariance_bias = Mat6::Zero();  ///< diagonal, from CandidateSelection's bias sds
  Mat6 covariance = Mat6::Zero();       ///< reported: spread + icp + bias
};

/// Keeps the best candidates by error and averages them on SO(3) x R^3 (the
/// thesis's "mean values"): the rotation by the chordal mean, the translation
/// by the arithmetic mean; then the covariance about that mean.
/// Throws std::invalid_argument on an empty input.
CandidateAverage average_best_candidates(std::span<const ExtrinsicCandidate> candidates, const CandidateSelection& selection = {});

/// Candidates that each fix only part of the extrinsic (degenerate registrations, whose weak translation is
/// the start's) fused by their information: X = argmin sum_k e_k^T Lambda_k e_k with e_k the [e_t, e_r]
/// tangent of X_k about X (Gauss-Newton, from `about`). Frames whose weak directions differ (turns) together
/// observe what none does alone.
struct InformationFusion {
  SE3 T_base_target;
  Mat6 information = Mat6::Zero();  ///< summed
  /// Inverse of the summed information, scaled by chi2 / dof when that exceeds 1 (the candidates disagree
  /// more than their information says), plus the bias term of CandidateSelection.
  Mat6 covariance = Mat6::Zero();
  double chi2_per_dof = 0.0;
  double translation_sd_m = 0.0;           ///< largest 1-sigma of covariance's translation block
  double rotation_sd_deg = 0.0;            ///< same for its rotation block
  double translation_observability = 0.0;  ///< lambda_min / lambda_max of the summed translation block
  Vec3 weak_direction = Vec3::Zero();      ///< its eigenvector of lambda_min
};
/// Throws std::invalid_argument on an empty input.
InformationFusion fuse_by_information(std::span<const ExtrinsicCandidate> candidates, const SE3& about,
                                      const CandidateSelection& selection = {});

}  // namespace mlidar::calib
