#include "mlidar/core/pose_uncertainty.hpp"

namespace mlidar {
namespace {

// The 3x3 blocks of a 6x6 covariance in [t, r] order.
struct CovarianceBlocks {
  Mat3 tt;  // translation-translation
  Mat3 tr;  // translation-rotation (E[rho phi^T])
  Mat3 rr;  // rotation-rotation
};

CovarianceBlocks split_blocks(const Mat6& covariance) {
  return {covariance.topLeftCorner<3, 3>(), covariance.topRightCorner<3, 3>(), covariance.bottomRightCorner<3, 3>()};
}

// Barfoot & Furgale's <<A>> = -tr(A) I + A; for u ~ N(0, A): E[u^ u^] = <<A>>.
Mat3 bracket(const Mat3& a) { return -a.trace() * Mat3::Identity() + a; }

// Their <<A, B>> = <<A>> <<B>> + <<B A>>. For zero-mean jointly Gaussian u, v with
// E[v u^T] = A and a constant B: E[u^ B^T v^T] = <<A, B>> (for symmetric A, B this is
// E[u^ B u^T] with A = E[u u^T]).
Mat3 bracket(const Mat3& a, const Mat3& b) { return bracket(a) * bracket(b) + bracket(b * a); }

// The 6x6 <<Sigma>> = E[xi^curl xi^curl] for xi ~ N(0, Sigma), xi^curl = [phi^, rho^; 0, phi^].
Mat6 bracket(const CovarianceBlocks& blocks) {
  Mat6 out = Mat6::Zero();
  out.topLeftCorner<3, 3>() = bracket(blocks.rr);
  out.topRightCorner<3, 3>() = bracket(Mat3(blocks.tr + blocks.tr.transpose()));
  out.bottomRightCorner<3, 3>() = bracket(blocks.rr);
  return out;
}

// B = 4 E[w w^T] for the BCH term w = 1/2 xi_a^curl xi_b', xi_a and xi_b' independent;
// w = 1/2 [phi_a^ rho_b + rho_a^ phi_b; phi_a^ phi_b].
Mat6 second_bch_term_moment(const CovarianceBlocks& a, const CovarianceBlocks& b) {
  const Mat3 b_tt = bracket(a.rr, b.tt) + bracket(a.tr.transpose(), b.tr) + bracket(a.tr, b.tr.transpose()) + bracket(a.tt, b.rr);
  const Mat3 b_tr = bracket(a.rr, b.tr.transpose()) + bracket(a.tr.transpose(), b.rr);
  const Mat3 b_rr = bracket(a.rr, b.rr);
  Mat6 out;
  out << b_tt, b_tr, b_tr.transpose(), b_rr;
  return out;
}

// Barfoot & Furgale 2014, sec. III (compounding poses), fourth-order covariance:
//   Sigma = Sigma_a + Sigma_b' + 1/12 (<<Sigma_a>> Sigma_b' + Sigma_b' <<Sigma_a>>^T
//           + <<Sigma_b'>> Sigma_a + Sigma_a <<Sigma_b'>>^T) + 1/4 B,
// with Sigma_b' = Ad(Ta) Sigma_b Ad(Ta)^T and B from the blocks of both. It comes from the
// BCH series xi = xi_a + xi_b' + 1/2 xi_a^curl xi_b' + 1/12 (xi_a^curl xi_a^curl xi_b'
// + xi_b'^curl xi_b'^curl xi_a) + ..., keeping the expectations of fourth-order products.
// Returns only the terms beyond Sigma_a + Sigma_b'.
Mat6 fourth_order_terms(const Mat6& sigma_a, const Mat6& sigma_b_moved) {
  const CovarianceBlocks a = split_blocks(sigma_a);
  const CovarianceBlocks b = split_blocks(sigma_b_moved);
  const Mat6 bracket_a = bracket(a);
  const Mat6 bracket_b = bracket(b);
  const Mat6 cross_terms =
      bracket_a * sigma_b_moved + sigma_b_moved * bracket_a.transpose() + bracket_b * sigma_a + sigma_a * bracket_b.transpose();
  return cross_terms / 12.0 + second_bch_term_moment(a, b) / 4.0;
}

// b's noise moved to the left of a.T: a.T Exp(xi_b) = Exp(Ad(a.T) xi_b) a.T.
Mat6 moved_covariance(const UncertainPose& a, const UncertainPose& b) {
  const Mat6 adjoint = a.T.adjoint();
  return adjoint * b.covariance * adjoint.transpose();
}

Mat6 symmetrized(const Mat6& m) { return 0.5 * (m + m.transpose()); }

}  // namespace

UncertainPose compound(const UncertainPose& a, const UncertainPose& b) {
  const Mat6 sigma_b_moved = moved_covariance(a, b);
  const Mat6 covariance = a.covariance + sigma_b_moved + fourth_order_terms(a.covariance, sigma_b_moved);
  return {a.T * b.T, symmetrized(covariance)};
}

Mat6 compound_covariance_second_order(const UncertainPose& a, const UncertainPose& b) {
  return symmetrized(a.covariance + moved_covariance(a, b));
}

Mat3 lidar_point_noise(const Vec3& p_lidar, double range_sigma_m, double angular_sigma_rad) {
  const double range_variance = range_sigma_m * range_sigma_m;
  const double range = p_lidar.norm();
  if (!(range > 0.0)) {
    return range_variance * Mat3::Identity();  // no bearing at the origin
  }
  const Vec3 bearing = p_lidar / range;
  const Mat3 along_beam = bearing * bearing.transpose();
  const double lateral_sigma_m = range * angular_sigma_rad;
  return range_variance * along_beam + lateral_sigma_m * lateral_sigma_m * (Mat3::Identity() - along_beam);
}

// eq 4.25-4.29: y = Exp(xi) T (p + zeta) ~= h + H theta with h = T p, theta = [xi; zeta],
// H = [(T p)^odot, R], q^odot = [I, -q^] (3x6 part, left perturbation, [t, r] order), and
// Sigma_y = H diag(Sigma_pose, Z) H^T.
Mat3 point_covariance(const UncertainPose& T_world_lidar, const Vec3& p_lidar, const Mat3& Z) {
  const Vec3 p_world = T_world_lidar.T * p_lidar;
  Eigen::Matrix<double, 3, 6> pose_jacobian;
  pose_jacobian << Mat3::Identity(), -hat(p_world);
  const Mat3 rotation = T_world_lidar.T.rotation_matrix();
  const Mat3 from_pose = pose_jacobian * T_world_lidar.covariance * pose_jacobian.transpose();
  const Mat3 from_point = rotation * Z * rotation.transpose();
  return from_pose + from_point;
}

BeamPointCovariance::BeamPointCovariance(const UncertainPose& T_world_lidar, double range_sigma_m, double angular_sigma_rad)
    : T_world_lidar_(T_world_lidar.T),
      R_(T_world_lidar.T.rotation_matrix()),
      sigma_tt_(T_world_lidar.covariance.topLeftCorner<3, 3>()),
      sigma_tr_(T_world_lidar.covariance.topRightCorner<3, 3>()),
      sigma_rr_(T_world_lidar.covariance.bottomRightCorner<3, 3>()),
      range_variance_(range_sigma_m * range_sigma_m),
      angular_variance_(angular_sigma_rad * angular_sigma_rad) {}

Mat3 BeamPointCovariance::operator()(const Vec3& p_lidar) const {
  const Vec3 rotated = R_ * p_lidar;
  const Vec3 p_world = rotated + T_world_lidar_.translation();
  const Mat3 P = -hat(p_world);
  const Mat3 cross = sigma_tr_ * P.transpose();
  Mat3 out = sigma_tt_ + cross + cross.transpose() + P * sigma_rr_ * P.transpose();  // eq 4.29, pose part
  const double range_squared = p_lidar.squaredNorm();
  if (!(range_squared > 0.0)) return out + range_variance_ * Mat3::Identity();  // no bearing at the origin
  const double lateral_variance = range_squared * angular_variance_;
  out += (range_variance_ - lateral_variance) / range_squared * (rotated * rotated.transpose());  // b b^T = R p p^T R^T / r^2
  out.diagonal().array() += lateral_variance;
  return out;
}

}  // namespace mlidar
