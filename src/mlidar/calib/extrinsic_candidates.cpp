#include "mlidar/calib/extrinsic_candidates.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/covariance.hpp"
#include "mlidar/core/rotation_average.hpp"
#include "mlidar/geometry/kdtree.hpp"

namespace mlidar::calib {
namespace {

std::vector<Eigen::Vector3f> finite_points(std::span<const Eigen::Vector3f> points) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  for (const auto& p : points)
    if (p.allFinite()) out.push_back(p);
  return out;
}

/// |{p in queries : some point of tree within radius}|.
std::size_t count_near(const std::vector<Eigen::Vector3f>& queries, const KdTree3f& tree, double radius_m) {
  const double radius_sq = radius_m * radius_m;
  std::size_t near = 0;
  for (const auto& q : queries) {
    const auto nearest = tree.knn(q, 1);
    if (!nearest.empty() && nearest.front().distance_sq <= radius_sq) ++near;
  }
  return near;
}

/// Tangent [e_t, e_r] of `candidate` about `mean`: t = t_mean + e_t, R = R_mean Exp(e_r).
Vec6 deviation(const SE3& mean, const SE3& candidate) {
  Vec6 e;
  e.head<3>() = candidate.translation() - mean.translation();
  e.tail<3>() = so3_log(mean.rotation().conjugate() * candidate.rotation());
  return e;
}

/// Inverse of a symmetric PSD matrix; a (near) singular one gets a tiny ridge so
/// its unobserved directions come out with a huge, finite variance.
Mat6 inverse_psd(const Mat6& information) {
  const double scale = std::max(information.diagonal().maxCoeff(), 1e-12);
  const Mat6 ridged = information + 1e-9 * scale * Mat6::Identity();
  return ridged.ldlt().solve(Mat6::Identity());
}

/// The shared-bias term of CandidateSelection, diagonal in [e_t, e_r].
Mat6 bias_covariance(const CandidateSelection& selection) {
  Vec6 variance;
  variance << Vec3::Constant(selection.bias_translation_sd_m * selection.bias_translation_sd_m),
      Vec3::Constant(std::pow(deg_to_rad(selection.bias_rotation_sd_deg), 2));
  return variance.asDiagonal();
}

}  // namespace

double overlap_factor(std::span<const Eigen::Vector3f> points_a, std::span<const Eigen::Vector3f> points_b, double radius_m) {
  std::vector<Eigen::Vector3f> a = finite_points(points_a);
  std::vector<Eigen::Vector3f> b = finite_points(points_b);
  if (a.empty() || b.empty()) return 0.0;
  const KdTree3f tree_a(a);
  const KdTree3f tree_b(b);
  const double ratio_a = static_cast<double>(count_near(a, tree_b, radius_m)) / static_cast<double>(a.size());
  const double ratio_b = static_cast<double>(count_near(b, tree_a, radius_m)) / static_cast<double>(b.size());
  return ratio_a * ratio_b;  // eq 3.14
}

Mat6 extrinsic_information(const Mat6& registration_hessian, double residual_variance, const SE3& T_world_base, const SE3& T_base_target) {
  Mat6 J = Mat6::Zero();
  J.topLeftCorner<3, 3>() = Mat3::Identity();
  J.topRightCorner<3, 3>() = -hat(T_base_target.translation());
  J.bottomRightCorner<3, 3>() = T_base_target.rotation_matrix().transpose();
  const Mat6 M = J * T_world_base.inverse().adjoint();  // e = M d
  const Mat6 M_inv = M.inverse();
  return M_inv.transpose() * registration_hessian * M_inv / std::max(residual_variance, 1e-12);
}

CandidateAverage average_best_candidates(std::span<const ExtrinsicCandidate> candidates, const CandidateSelection& selection) {
  if (candidates.empty()) throw std::invalid_argument("average_best_candidates: no candidates");
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  // Ties broken by frame so the choice never depends on the input order.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    if (candidates[i].error_m != candidates[j].error_m) return candidates[i].error_m < candidates[j].error_m;
    return candidates[i].frame < candidates[j].frame;
  });
  const auto wanted = static_cast<std::size_t>(selection.keep_fraction * static_cast<double>(candidates.size()) + 0.5);
  const std::size_t keep = std::min(candidates.size(), std::max(wanted, selection.min_keep));
  CandidateAverage out;
  out.kept.assign(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep));

  std::vector<Quat> rotations;
  Vec3 translation_sum = Vec3::Zero();
  Mat6 information = Mat6::Zero();
  for (const std::size_t i : out.kept) {
    rotations.push_back(candidates[i].T_base_target.rotation());
    translation_sum += candidates[i].T_base_target.translation();
    information += candidates[i].information;
  }
  out.T_base_target = SE3(chordal_mean(rotations), translation_sum / static_cast<double>(keep));

  Mat6 scatter = Mat6::Zero();
  for (const std::size_t i : out.kept) {
    const Vec6 e = deviation(out.T_base_target, candidates[i].T_base_target);
    scatter += e * e.transpose();
  }
  // Sample covariance, not divided by n: the candidates share the base's map
  // and odometry errors, so their mean is not n times better than one of them.
  if (keep > 1) out.covariance_spread = scatter / (static_cast<double>(keep) - 1.0);
  out.covariance_icp = inverse_psd(information);
  out.covariance_bias = bias_covariance(selection);
  out.covariance = out.covariance_spread + out.covariance_icp + out.covariance_bias;
  return out;
}

InformationFusion fuse_by_information(std::span<const ExtrinsicCandidate> candidates, const SE3& about,
                                      const CandidateSelection& selection) {
  if (candidates.empty()) throw std::invalid_argument("fuse_by_information: no candidates");
  InformationFusion out;
  out.T_base_target = about;
  for (const auto& c : candidates) out.information += c.information;
  const Mat6 covariance = inverse_psd(out.information);
  for (int iteration = 0; iteration < 5; ++iteration) {
    Vec6 gradient = Vec6::Zero();
    for (const auto& c : candidates) gradient += c.information * deviation(out.T_base_target, c.T_base_target);
    const Vec6 step = covariance * gradient;
    out.T_base_target = SE3(out.T_base_target.rotation() * so3_exp(step.tail<3>()), out.T_base_target.translation() + step.head<3>());
    if (step.norm() < 1e-10) break;
  }
  double chi2 = 0.0;
  for (const auto& c : candidates) {
    const Vec6 e = deviation(out.T_base_target, c.T_base_target);
    chi2 += e.dot(c.information * e);
  }
  const double dof = 6.0 * static_cast<double>(candidates.size() - 1);
  out.chi2_per_dof = dof > 0.0 ? chi2 / dof : 0.0;
  out.covariance = covariance * std::max(1.0, out.chi2_per_dof) + bias_covariance(selection);
  out.translation_sd_m = largest_sd(out.covariance.topLeftCorner<3, 3>());
  out.rotation_sd_deg = rad_to_deg(largest_sd(out.covariance.bottomRightCorner<3, 3>()));
  const Eigen::SelfAdjointEigenSolver<Mat3> translation(out.information.topLeftCorner<3, 3>());
  const Vec3 spread = translation.eigenvalues();
  out.translation_observability = spread(2) > 0.0 ? spread(0) / spread(2) : 0.0;
  out.weak_direction = translation.eigenvectors().col(0);
  return out;
}

}  // namespace mlidar::calib
