#pragma once
// Uncertain poses and the uncertainty of LiDAR points seen from them.
// Convention: a LEFT perturbation, T = Exp(xi) * T_mean with xi ~ N(0, Sigma);
// xi = [rho, phi] (translation first, Barfoot's order), Sigma is 6x6 in
// [t, r] order, units m^2 (translation block), rad^2 (rotation block) and
// m rad (cross block). Sigma is expressed in the frame the pose maps into
// (for T_world_lidar: the world frame).
#include "mlidar/core/se3.hpp"

namespace mlidar {

/// A pose with a left-perturbation covariance (see the file comment).
struct UncertainPose {
  SE3 T;
  Mat6 covariance = Mat6::Zero();
};

/// The compound a.T * b.T of two independent uncertain poses, with the covariance
/// of Exp(xi_a) a.T Exp(xi_b) b.T = Exp(xi) a.T b.T to fourth order in the noise
/// (Barfoot & Furgale 2014, sec. III). Exact when b's covariance is zero.
UncertainPose compound(const UncertainPose& a, const UncertainPose& b);

/// The second-order (first-order propagation) covariance of the same compound:
/// a.covariance + Ad(a.T) b.covariance Ad(a.T)^T. Cheaper; too small when the
/// rotation sigmas reach ~0.2 rad.
Mat6 compound_covariance_second_order(const UncertainPose& a, const UncertainPose& b);

/// Noise covariance Z (m^2, LiDAR frame) of a point p_lidar (m) measured by a LiDAR with
/// range 1-sigma range_sigma_m (m) and bearing 1-sigma angular_sigma_rad (rad, per axis):
/// sigma_r^2 u u^T + (r sigma_theta)^2 (I - u u^T), u = p / r, r = |p|. A point at
/// p = 0 has no bearing; it gets sigma_r^2 I.
Mat3 lidar_point_noise(const Vec3& p_lidar, double range_sigma_m, double angular_sigma_rad);

/// Covariance (m^2, world frame) of y = Exp(xi) T_world_lidar.T (p_lidar + zeta), with the pose
/// noise xi ~ N(0, T_world_lidar.covariance) independent of the point noise zeta ~ N(0, Z)
/// (Z in the LiDAR frame, m^2), to first order: H diag(Sigma_pose, Z) H^T,
/// H = [I, -(T p)^, R].
Mat3 point_covariance(const UncertainPose& T_world_lidar, const Vec3& p_lidar, const Mat3& Z);

/// point_covariance(T_world_lidar, p, lidar_point_noise(p, range_sigma_m, angular_sigma_rad)) for many points of one
/// LiDAR pose, in closed form: R Z R^T = s_l^2 I + (s_r^2 - s_l^2) b b^T with b the world bearing R p / |p| and
/// s_l = |p| angular_sigma_rad, and J Sigma J^T for J = [I, P], P = -(T p)^, as Sigma_tt + Sigma_tr P^T + P Sigma_rt
/// + P Sigma_rr P^T (the rotation matrix and the covariance blocks taken once per pose).
class BeamPointCovariance {
 public:
  BeamPointCovariance(const UncertainPose& T_world_lidar, double range_sigma_m, double angular_sigma_rad);
  /// The covariance (m^2, world frame) of the point p_lidar (m, LiDAR frame).
  Mat3 operator()(const Vec3& p_lidar) const;

 private:
  SE3 T_world_lidar_;
  Mat3 R_;
  Mat3 sigma_tt_, sigma_tr_, sigma_rr_;
  double range_variance_;
  double angular_variance_;
};

}  // namespace mlidar
