#include "mlidar/geometry/plane_fit.hpp"

#include <cassert>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace mlidar {

double PlaneFit::rms() const { return std::sqrt(std::max(0.0, eigenvalues(0))); }

PlaneFit fit_plane(std::span<const Eigen::Vector3f> points, std::span<const std::uint32_t> indices) {
  assert(indices.size() >= 3);
  PlaneFit fit;
  fit.count = indices.size();
  const double n = static_cast<double>(indices.size());
  for (const std::uint32_t i : indices) fit.centroid += points[i].cast<double>();
  fit.centroid /= n;
  Mat3 scatter = Mat3::Zero();
  for (const std::uint32_t i : indices) {
    const Vec3 q = points[i].cast<double>() - fit.centroid;
    scatter.noalias() += q * q.transpose();
  }
  scatter /= n;
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(scatter);
  fit.eigenvalues = eig.eigenvalues();
  const Mat3 axes = eig.eigenvectors();
  fit.plane.normal = axes.col(0);
  fit.plane.offset = -fit.plane.normal.dot(fit.centroid);

  const double noise_var = std::max(0.0, fit.eigenvalues(0)) * n / std::max(1.0, n - 3.0);
  Mat3 cov_n = Mat3::Zero();
  for (int k = 1; k < 3; ++k) {
    const double lambda = fit.eigenvalues(k);
    const double inv = lambda > 0.0 ? 1.0 / lambda : std::numeric_limits<double>::infinity();
    cov_n += inv * axes.col(k) * axes.col(k).transpose();
  }
  cov_n *= noise_var / n;
  fit.covariance.topLeftCorner<3, 3>() = cov_n;
  const Vec3 cross = -cov_n * fit.centroid;
  fit.covariance.topRightCorner<3, 1>() = cross;
  fit.covariance.bottomLeftCorner<1, 3>() = cross.transpose();
  fit.covariance(3, 3) = fit.centroid.dot(cov_n * fit.centroid) + noise_var / n;
  return fit;
}

}  // namespace mlidar
