#pragma once
// Small summaries of covariance matrices used by the calibrations' verdicts.
#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "mlidar/core/so3.hpp"

namespace mlidar {

/// The largest 1-sigma of a 3x3 covariance block: sqrt of its largest eigenvalue (0 for a negative one).
inline double largest_sd(const Mat3& block) {
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Mat3>(block).eigenvalues()(2)));
}

}  // namespace mlidar
