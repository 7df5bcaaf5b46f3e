#pragma once
// The frame a job writes its results in, and the LiDAR it estimates in. When
// the dataset's base frame B is a LiDAR, the two are the same. When B is a
// frame that is no LiDAR (a vehicle's), the reference LiDAR R places it with
// its known extrinsic T_B_R (dataset.yaml reference_lidar): slam and
// calibrate auto estimate relative to R and convert here, for
//   extrinsics:  T_B_j = T_B_R T_R_j; covariance [t additive, r local]:
//                dt' = R_BR dt, dr' = dr, so Sigma' = J Sigma J^T with J = diag(R_BR, I)
//   poses:       T_w_B(k) = T_B_R T_w_R(k) T_B_R^-1 (the world is B at the first frame, as R's was R's)
//   map points:  p_w_B = T_B_R p_w_R
#include <cstddef>
#include <optional>
#include <string>

#include "mlidar/core/se3.hpp"
#include "mlidar/io/frame_source.hpp"

namespace mlidar::pipelines {

struct BaseFrame {
  std::string name;           ///< B, as extrinsics.yaml's base
  std::size_t reference = 0;  ///< R's index in the source's lidars()
  SE3 T_base_reference;       ///< T_B_R; identity when B is R
  bool is_reference = true;   ///< B is R: every conversion is the identity (and returns its input exactly)

  SE3 extrinsic_to_base(const SE3& T_reference_lidar) const;
  SE3 extrinsic_to_reference(const SE3& T_base_lidar) const;
  Mat6 covariance_to_base(const Mat6& covariance_reference) const;
  Mat6 covariance_to_reference(const Mat6& covariance_base) const;  ///< the inverse: J = diag(R_BR^T, I)
  SE3 pose_to_base(const SE3& T_world_reference) const;
  Eigen::Vector3f point_to_base(const Eigen::Vector3f& p_world_reference) const;
};

/// The source's: B from dataset.yaml and R its base LiDAR or reference_lidar. UsageError when R is not among the
/// LiDARs the source reads.
BaseFrame base_frame(const io::FrameSource& source);

}  // namespace mlidar::pipelines
