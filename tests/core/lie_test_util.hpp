#pragma once
// Seeded random samples and numeric derivatives shared by the core Lie tests.
#include <cmath>
#include <numbers>
#include <random>

#include "mlidar/core/se3.hpp"
#include "pose_error.hpp"

namespace mlidar::test {

inline Vec3 random_unit_vector(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Vec3 v(normal(rng), normal(rng), normal(rng));
  return v.normalized();
}

/// Rotation vector with angle uniform in [min_angle, max_angle] (log-uniform
/// when log_scale is set, for tiny angles) and a random axis.
inline Vec3 random_rotation_vector(std::mt19937& rng, double min_angle, double max_angle, bool log_scale = false) {
  double angle = 0.0;
  if (log_scale) {
    std::uniform_real_distribution<double> exponent(std::log(min_angle), std::log(max_angle));
    angle = std::exp(exponent(rng));
  } else {
    std::uniform_real_distribution<double> uniform(min_angle, max_angle);
    angle = uniform(rng);
  }
  return angle * random_unit_vector(rng);
}

inline Vec6 random_twist(std::mt19937& rng, double min_angle, double max_angle, bool log_scale = false) {
  std::uniform_real_distribution<double> unit(-5.0, 5.0);
  Vec6 xi;
  xi << unit(rng), unit(rng), unit(rng), random_rotation_vector(rng, min_angle, max_angle, log_scale);
  return xi;
}

inline SE3 random_pose(std::mt19937& rng) { return SE3::exp(random_twist(rng, 0.0, std::numbers::pi)); }

/// Max-abs difference of two poses' 4x4 matrices.
inline double pose_distance(const SE3& a, const SE3& b) { return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff(); }

/// Central differences of a map R^n -> R^m: column j is (f(x + h e_j) - f(x - h e_j)) / 2h.
template <int M, int N, typename F>
Eigen::Matrix<double, M, N> numeric_jacobian(F&& f, const Eigen::Matrix<double, N, 1>& x, double h = 1e-6) {
  Eigen::Matrix<double, M, N> jac;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix<double, N, 1> step = Eigen::Matrix<double, N, 1>::Zero();
    step(j) = h;
    jac.col(j) = (f(x + step) - f(x - step)) / (2.0 * h);
  }
  return jac;
}

}  // namespace mlidar::test
