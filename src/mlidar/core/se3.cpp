#include "mlidar/core/se3.hpp"

#include <Eigen/SVD>

namespace mlidar {

SE3::SE3(const Quat& rotation, const Vec3& translation)
    : rotation_(rotation.normalized()), translation_(translation) {}

SE3 SE3::from_matrix(const Mat4& matrix) {
  const Mat3 r = matrix.topLeftCorner<3, 3>();
  Eigen::JacobiSVD<Mat3> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 r_ortho = svd.matrixU() * svd.matrixV().transpose();
  if (r_ortho.determinant() < 0.0) {
    Mat3 u = svd.matrixU();
    u.col(2) *= -1.0;
    r_ortho = u * svd.matrixV().transpose();
  }
  return {Quat(r_ortho), matrix.topRightCorner<3, 1>()};
}

Mat4 SE3::matrix() const {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = rotation_matrix();
  m.topRightCorner<3, 1>() = translation_;
  return m;
}

SE3 SE3::inverse() const {
  const Quat r_inv = rotation_.conjugate();
  return {r_inv, -(r_inv * translation_)};
}

SE3 SE3::operator*(const SE3& other) const {
  return {rotation_ * other.rotation_, rotation_ * other.translation_ + translation_};
}

SE3 SE3::exp(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  return {so3_exp(phi), so3_left_jacobian(phi) * rho};
}

Vec6 SE3::log() const {
  const Vec3 phi = so3_log(rotation_);
  Vec6 xi;
  xi.head<3>() = so3_left_jacobian_inverse(phi) * translation_;
  xi.tail<3>() = phi;
  return xi;
}

Mat6 SE3::adjoint() const {
  const Mat3 r = rotation_matrix();
  Mat6 ad = Mat6::Zero();
  ad.topLeftCorner<3, 3>() = r;
  ad.topRightCorner<3, 3>() = hat(translation_) * r;
  ad.bottomRightCorner<3, 3>() = r;
  return ad;
}

}  // namespace mlidar
