#include "mlidar/core/rotation_average.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/SVD>

namespace mlidar {
namespace {

void check_weights(std::span<const Quat> rotations, std::span<const double> weights) {
  if (rotations.empty()) throw std::invalid_argument("rotation mean: no rotations given (expected at least one)");
  if (weights.empty()) return;
  if (weights.size() != rotations.size()) {
    throw std::invalid_argument("rotation mean: " + std::to_string(weights.size()) + " weights for " + std::to_string(rotations.size()) +
                                " rotations (expected one each)");
  }
  double total = 0.0;
  for (const double w : weights) {
    if (!std::isfinite(w) || w < 0.0) {
      throw std::invalid_argument("rotation mean: weight " + std::to_string(w) + " (expected a finite value >= 0)");
    }
    total += w;
  }
  if (!(total > 0.0)) throw std::invalid_argument("rotation mean: all weights are zero (expected one > 0)");
}

// Nearest rotation to m in Frobenius norm: U diag(1, 1, det(U V^T)) V^T.
Mat3 project_to_rotation(const Mat3& m) {
  const Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 u = svd.matrixU();
  if ((u * svd.matrixV().transpose()).determinant() < 0.0) u.col(2) *= -1.0;
  return u * svd.matrixV().transpose();
}

}  // namespace

Quat chordal_mean(std::span<const Quat> rotations, std::span<const double> weights) {
  check_weights(rotations, weights);
  Mat3 sum = Mat3::Zero();
  for (std::size_t i = 0; i < rotations.size(); ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    sum += w * rotations[i].normalized().toRotationMatrix();
  }
  return Quat(project_to_rotation(sum)).normalized();
}

RobustMeanResult robust_rotation_mean(std::span<const Quat> rotations, const RobustMeanOptions& options) {
  RobustMeanResult result;
  result.mean = chordal_mean(rotations);
  for (result.iterations = 0; result.iterations < options.max_iterations; ++result.iterations) {
    const Quat mean_inv = result.mean.conjugate();
    Vec3 weighted_sum = Vec3::Zero();
    double weight_sum = 0.0;
    for (const Quat& r : rotations) {
      const Vec3 v = so3_log(mean_inv * r);
      const double w = 1.0 / std::max(v.norm(), options.min_distance);
      weighted_sum += w * v;
      weight_sum += w;
    }
    const Vec3 step = weighted_sum / weight_sum;
    result.mean = (result.mean * so3_exp(step)).normalized();
    if (step.norm() < options.step_tolerance) {
      result.converged = true;
      ++result.iterations;
      break;
    }
  }
  const Quat mean_inv = result.mean.conjugate();
  for (const Quat& r : rotations) result.cost += so3_log(mean_inv * r).norm();
  return result;
}

}  // namespace mlidar
