#pragma once
// Means of a set of rotations (e.g. extrinsic estimates from several windows).
#include <span>

#include "mlidar/core/so3.hpp"

namespace mlidar {

/// Chordal L2 mean: the rotation nearest (Frobenius) to sum_i w_i R_i, found by
/// SVD projection (Hartley et al., "Rotation Averaging", IJCV 2013, sec 5.3).
/// `weights` is empty (all 1) or one non-negative finite weight per rotation.
/// Throws std::invalid_argument on an empty input, a size mismatch, a negative
/// or non-finite weight, or all-zero weights.
Quat chordal_mean(std::span<const Quat> rotations, std::span<const double> weights = {});

struct RobustMeanOptions {
  int max_iterations = 100;
  double step_tolerance = 1e-12;  ///< stop when an update rotates by less (rad)
  double min_distance = 1e-12;    ///< floor on d_i in the weights 1/d_i (rad)
};

struct RobustMeanResult {
  Quat mean = Quat::Identity();
  int iterations = 0;
  bool converged = false;  ///< step fell below step_tolerance
  double cost = 0.0;       ///< sum_i d(mean, R_i), geodesic L1 (rad)
};

/// Geodesic L1 mean (the median on SO(3)) by the Weiszfeld iteration of
/// Hartley, Aftab, Trumpf, "L1 rotation averaging using the Weiszfeld
/// algorithm", CVPR 2011, Alg. 1: start from the chordal mean, then
///   v_i = Log(R^-1 R_i),  R <- R Exp(sum_i v_i / d_i / sum_i 1 / d_i).
/// Outliers pull with unit force whatever their distance, so a minority of
/// gross outliers barely moves the result. Throws like chordal_mean on empty input.
RobustMeanResult robust_rotation_mean(std::span<const Quat> rotations, const RobustMeanOptions& options = {});

}  // namespace mlidar
