#include "mlidar/pipelines/base_frame.hpp"

#include "mlidar/core/error.hpp"

namespace mlidar::pipelines {

SE3 BaseFrame::extrinsic_to_base(const SE3& T_reference_lidar) const {
  return is_reference ? T_reference_lidar : T_base_reference * T_reference_lidar;
}

SE3 BaseFrame::extrinsic_to_reference(const SE3& T_base_lidar) const {
  return is_reference ? T_base_lidar : T_base_reference.inverse() * T_base_lidar;
}

SE3 BaseFrame::pose_to_base(const SE3& T_world_reference) const {
  return is_reference ? T_world_reference : T_base_reference * T_world_reference * T_base_reference.inverse();
}

Eigen::Vector3f BaseFrame::point_to_base(const Eigen::Vector3f& p_world_reference) const {
  if (is_reference) return p_world_reference;
  const Vec3 p = T_base_reference * Vec3(p_world_reference.cast<double>());
  return p.cast<float>();
}

namespace {

/// A [t additive, r local] covariance with its translation block turned by R (the rotation's block is local).
Mat6 translation_rotated(const Mat6& covariance, const Mat3& R) {
  Mat6 J = Mat6::Identity();
  J.topLeftCorner<3, 3>() = R;
  return J * covariance * J.transpose();
}

}  // namespace

Mat6 BaseFrame::covariance_to_base(const Mat6& covariance_reference) const {
  if (is_reference) return covariance_reference;
  return translation_rotated(covariance_reference, T_base_reference.rotation().toRotationMatrix());
}

Mat6 BaseFrame::covariance_to_reference(const Mat6& covariance_base) const {
  if (is_reference) return covariance_base;
  return translation_rotated(covariance_base, T_base_reference.rotation().toRotationMatrix().transpose());
}

BaseFrame base_frame(const io::FrameSource& source) {
  BaseFrame frame;
  frame.name = source.dataset_info() ? source.dataset_info()->base : source.lidars().front().name;
  const std::optional<std::size_t> reference = source.reference_index();
  if (!reference) throw UsageError("the LiDAR that defines the base frame " + frame.name + " is not among the LiDARs read");
  frame.reference = *reference;
  frame.is_reference = source.lidars()[*reference].name == frame.name;
  if (!frame.is_reference) frame.T_base_reference = *source.lidars()[*reference].initial_extrinsic;  // required by dataset.yaml's rules
  return frame;
}

}  // namespace mlidar::pipelines
