#pragma once
// Least-squares plane through points by PCA (thesis eq 2.2: minimise the sum
// of squared point-to-plane distances, eq 2.1), with the first-order
// covariance of the fitted normal and offset.
#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "mlidar/core/so3.hpp"

namespace mlidar {

/// Plane n.p + d = 0 with |n| = 1 (eq 2.1 with beta = [n, d]).
struct Plane {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;
  double signed_distance(const Vec3& point) const { return normal.dot(point) + offset; }
  Plane flipped() const { return {-normal, -offset}; }
};

struct PlaneFit {
  Plane plane;
  Vec3 centroid = Vec3::Zero();
  Vec3 eigenvalues = Vec3::Zero();  ///< of the scatter matrix / count, ascending (eigenvalues(0) = residual variance)
  std::size_t count = 0;
  /// Covariance of [n, d] (4x4) to first order, with the noise variance
  /// estimated from the residuals: Cov(n) = s^2/N sum_{k=1,2} e_k e_k^T / lambda_k,
  /// d = -n.c so Var(d) = c^T Cov(n) c + s^2/N, Cov(n, d) = -Cov(n) c.
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  double rms() const;
};

/// Fit to points[indices]. Precondition (asserted): at least 3 indices, all in range.
/// A collinear or repeated set gives a plane with an arbitrary normal about the line
/// and an infinite covariance; callers check eigenvalues(1) > 0.
PlaneFit fit_plane(std::span<const Eigen::Vector3f> points, std::span<const std::uint32_t> indices);

}  // namespace mlidar
