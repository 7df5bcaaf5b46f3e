#include "mlidar/geometry/kabsch.hpp"

#include <cassert>

#include <Eigen/SVD>

namespace mlidar {

Mat3 kabsch_rotation(std::span<const Vec3> src, std::span<const Vec3> dst) {
  assert(src.size() == dst.size());
  Mat3 cross = Mat3::Zero();
  for (std::size_t i = 0; i < src.size(); ++i) cross.noalias() += src[i] * dst[i].transpose();
  const Eigen::JacobiSVD<Mat3> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Mat3 u = svd.matrixU();
  const Mat3 v = svd.matrixV();
  Mat3 d = Mat3::Identity();
  d(2, 2) = (v * u.transpose()).determinant() < 0.0 ? -1.0 : 1.0;  // eq 2.6: no reflection
  return v * d * u.transpose();
}

}  // namespace mlidar
