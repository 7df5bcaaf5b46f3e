#include "mlidar/eval/alignment.hpp"

#include <Eigen/SVD>

#include "mlidar/core/error.hpp"

namespace mlidar::eval {

const char* align_mode_name(AlignMode mode) {
  switch (mode) {
    case AlignMode::kNone:
      return "none";
    case AlignMode::kOrigin:
      return "origin";
    case AlignMode::kSe3:
      return "se3";
    case AlignMode::kSim3:
      return "sim3";
  }
  return "none";
}

SE3 Alignment::apply(const SE3& T_world_est) const {
  return SE3(T_gt_est.rotation() * T_world_est.rotation(),
             scale * (T_gt_est.rotation() * T_world_est.translation()) + T_gt_est.translation());
}

Alignment umeyama_alignment(const std::vector<Vec3>& src, const std::vector<Vec3>& dst, bool with_scale, const std::string& source) {
  if (src.size() != dst.size() || src.size() < 3)
    throw InputError(
        source, "positions",
        "at least 3 associated poses are needed to align (got " + std::to_string(src.size()) + "); use --align origin or none");
  const double n = static_cast<double>(src.size());
  Vec3 mean_src = Vec3::Zero();
  Vec3 mean_dst = Vec3::Zero();
  for (std::size_t i = 0; i < src.size(); ++i) {
    mean_src += src[i];
    mean_dst += dst[i];
  }
  mean_src /= n;
  mean_dst /= n;
  // eq 38 (variance of src) and eq 39 (cross-covariance Sigma_xy = 1/n sum (dst - mu_dst)(src - mu_src)^T)
  double variance_src = 0.0;
  Mat3 cross_covariance = Mat3::Zero();
  for (std::size_t i = 0; i < src.size(); ++i) {
    const Vec3 centred_src = src[i] - mean_src;
    variance_src += centred_src.squaredNorm();
    cross_covariance += (dst[i] - mean_dst) * centred_src.transpose();
  }
  variance_src /= n;
  cross_covariance /= n;
  if (!(variance_src > 1e-12))
    throw InputError(source, "positions", "all estimated positions coincide; cannot align (use --align origin or none)");
  // eqs 40-43: R = U S V^T with S = diag(1, 1, -1) when det(U) det(V) < 0; s = tr(D S) / sigma_src^2.
  const Eigen::JacobiSVD<Mat3> svd(cross_covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Vec3 signs = Vec3::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) signs.z() = -1.0;
  const Mat3 rotation = svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();
  Alignment alignment;
  alignment.mode = with_scale ? AlignMode::kSim3 : AlignMode::kSe3;
  alignment.scale = with_scale ? svd.singularValues().dot(signs) / variance_src : 1.0;
  alignment.T_gt_est = SE3(Quat(rotation).normalized(), mean_dst - alignment.scale * (rotation * mean_src));
  return alignment;
}

Alignment compute_alignment(AlignMode mode, const std::vector<SE3>& gt, const std::vector<SE3>& est, const std::string& source) {
  Alignment alignment;
  alignment.mode = mode;
  if (mode == AlignMode::kNone || gt.empty()) return alignment;
  if (mode == AlignMode::kOrigin) {
    alignment.T_gt_est = gt.front() * est.front().inverse();  // evo align_origin: T_gt0 T_est0^-1
    return alignment;
  }
  std::vector<Vec3> src(est.size());
  std::vector<Vec3> dst(gt.size());
  for (std::size_t i = 0; i < est.size(); ++i) src[i] = est[i].translation();
  for (std::size_t i = 0; i < gt.size(); ++i) dst[i] = gt[i].translation();
  return umeyama_alignment(src, dst, mode == AlignMode::kSim3, source);
}

}  // namespace mlidar::eval
