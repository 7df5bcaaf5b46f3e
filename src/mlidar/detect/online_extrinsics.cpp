#include "mlidar/detect/online_extrinsics.hpp"

#include "mlidar/core/extrinsic_perturbation.hpp"

namespace mlidar::detect {

calib::PairRefineConfig online_refine_config() {
  calib::PairRefineConfig config;
  config.search_mode = calib::PairSearchMode::kNever;
  // Lighter than `calibrate refine`'s, measured on 20 simulated lyft test frames x 2 LiDARs at alpha 0.04 and 0.1
  // (docs/benchmarks.md, "Online calibration in the loop"): 40 of 40 trusted, 0.016 deg mean rotation error, against
  // 0.022 deg with the defaults; on an idle machine 59 ms a frame's two registrations against 300 ms (bench_detect). A frame's side LiDAR sees much that the top
  // one does not: the default overlap check (0.3) distrusted a quarter of these registrations, each within 0.05 deg.
  config.icp.levels = {{0.5, 1.0, 0.2}, {0.2, 0.4, 0.05}};
  config.icp.max_points = 3000;
  config.ref_voxel_size = 0.2;
  config.symmetric = false;
  config.min_overlap = 0.15;
  return config;
}

RefinedExtrinsic refine_extrinsic_online(const Scan& reference, const SE3& T_base_reference, const Scan& lidar,
                                         const SE3& T_base_lidar_given, const calib::PairRefineConfig& config) {
  RefinedExtrinsic out;
  out.registration = calib::refine_pair(reference.points, lidar.points, T_base_reference.inverse() * T_base_lidar_given, config);
  const SE3 T_base_lidar = out.trusted() ? T_base_reference * out.registration.T_ref_target : T_base_lidar_given;
  // The registration's covariance is [t additive, r on the left of R] in the reference frame; in the base frame
  // both blocks turn by R_base_reference (t_base = R t + t_ref, R_base = Exp(R r) R R_ref_lidar): eq 6.1-6.2's
  // (rho, phi), which perturbation_as_left_covariance turns into point_covariance's left perturbation.
  Mat6 rotate = Mat6::Zero();
  rotate.topLeftCorner<3, 3>() = rotate.bottomRightCorner<3, 3>() = T_base_reference.rotation_matrix();
  const Mat6 rho_phi = rotate * out.registration.covariance * rotate.transpose();
  out.uncertain_extrinsic = {T_base_lidar, perturbation_as_left_covariance(rho_phi, T_base_lidar)};
  return out;
}

}  // namespace mlidar::detect
