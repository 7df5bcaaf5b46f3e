#include "mlidar/calib/online_hand_eye.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "mlidar/calib/hand_eye_linear.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

void validate(const OnlineHandEyeConfig& c) {
  const bool ok = c.max_constraints >= 2 && c.rotation_threshold > 0.0 && c.huber_delta_rad > 0.0 && c.planar_ratio > 0.0 &&
                  c.planar_ratio < 1.0 && c.translation_min_ratio > 0.0 && c.translation_min_ratio < c.planar_ratio &&
                  c.translation_max_std_m > 0.0 && c.translation_min_pairs >= 2 && c.planar_min_condition > 0.0 &&
                  c.planar_min_condition < 1.0;
  if (!ok) {
    throw std::invalid_argument(
        "OnlineHandEyeConfig: max_constraints >= 2, translation_min_pairs >= 2, thresholds > 0, "
        "0 < translation_min_ratio < planar_ratio < 1, 0 < planar_min_condition < 1");
  }
}

bool finite(const SE3& T) { return T.rotation().coeffs().allFinite() && T.translation().allFinite(); }

double pair_rotation_angle(const MotionPair& pair) {
  return std::min(so3_log(pair.A.rotation()).norm(), so3_log(pair.B.rotation()).norm());
}

/// IRLS weight of the Huber loss, rho'(phi) / phi: 1 inside delta, delta / phi beyond.
double huber_weight(double phi, double delta) { return phi <= delta ? 1.0 : delta / phi; }

struct TranslationSystem {
  Mat3 normal = Mat3::Zero();
  Vec3 rhs = Vec3::Zero();
};

/// Eq 4.18 normal equations, rows (R_A - I) t = R t_B - t_A scaled by w_k like
/// eq 4.16's, over the pairs whose translation is valid.
TranslationSystem translation_system(std::span<const MotionPair> pairs, std::span<const double> weights, const std::vector<bool>& valid,
                                     const Quat& R_base_lidar) {
  TranslationSystem s;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!valid[k]) continue;
    const double w2 = weights[k] * weights[k];
    const Mat3 M = pairs[k].A.rotation_matrix() - Mat3::Identity();
    const Vec3 b = R_base_lidar * pairs[k].B.translation() - pairs[k].A.translation();
    s.normal += w2 * M.transpose() * M;
    s.rhs += w2 * M.transpose() * b;
  }
  return s;
}

/// Eq 4.18's predicted standard deviation of t over the eigen-directions
/// `first`..2 of `eig`: residual variance (weighted, per solved dimension) / lambda_min.
double translation_std(std::span<const MotionPair> pairs, std::span<const double> weights, const std::vector<bool>& valid, const SE3& X,
                       const Eigen::SelfAdjointEigenSolver<Mat3>& eig, int first) {
  double rss = 0.0;
  double rows = 0.0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!valid[k]) continue;
    const Vec3 e = (pairs[k].A.rotation_matrix() - Mat3::Identity()) * X.translation() + pairs[k].A.translation() -
                   X.rotation() * pairs[k].B.translation();
    rss += weights[k] * weights[k] * e.squaredNorm();
    rows += 3.0;
  }
  const double dof = rows - static_cast<double>(3 - first);
  if (!(dof > 0.0) || !(eig.eigenvalues()(first) > 0.0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(rss / dof / eig.eigenvalues()(first));
}

/// The common rotation axis with its largest component positive (a stable sign for the report).
Vec3 signed_common_axis(std::span<const MotionPair> pairs) {
  const Vec3 axis = common_rotation_axis(pairs);
  Eigen::Index largest = 0;
  axis.cwiseAbs().maxCoeff(&largest);
  return axis(largest) < 0.0 ? Vec3(-axis) : axis;
}

}  // namespace

std::string_view to_string(OnlineHandEyeState state) {
  switch (state) {
    case OnlineHandEyeState::collecting:
      return "collecting";
    case OnlineHandEyeState::rotation_ready:
      return "rotation_ready";
    case OnlineHandEyeState::ready:
      return "ready";
  }
  return "unknown";
}

double hand_eye_residual_angle(const MotionPair& pair, const Quat& R_base_lidar) {
  // Eq 4.17 in this convention: A X = X B  <=>  X^-1 A^-1 X B = I.
  const Quat r = R_base_lidar.conjugate() * pair.A.rotation().conjugate() * R_base_lidar * pair.B.rotation();
  return 2.0 * std::atan2(r.vec().norm(), std::abs(r.w()));
}

OnlineHandEye::OnlineHandEye(OnlineHandEyeConfig config) : config_(config) { validate(config_); }

void OnlineHandEye::reset() {
  pairs_.clear();
  rotation_angles_.clear();
  translation_valid_.clear();
  status_ = {};
}

PairOutcome OnlineHandEye::add(const MotionPair& pair, bool translation_valid) {
  ++status_.pairs_seen;
  if (!finite(pair.A) || !finite(pair.B)) return PairOutcome::rejected_invalid;
  const double angle = pair_rotation_angle(pair);
  PairOutcome outcome = PairOutcome::stored;
  if (pairs_.size() < config_.max_constraints) {
    pairs_.push_back(pair);
    rotation_angles_.push_back(angle);
    translation_valid_.push_back(translation_valid);
  } else {
    // Sec. 4.6.2.1: a bounded priority store; constraints with small rotation are removed.
    const auto smallest = std::min_element(rotation_angles_.begin(), rotation_angles_.end());
    if (angle <= *smallest) return PairOutcome::dropped_small;
    const auto index = static_cast<std::size_t>(std::distance(rotation_angles_.begin(), smallest));
    pairs_[index] = pair;
    rotation_angles_[index] = angle;
    translation_valid_[index] = translation_valid;
    outcome = PairOutcome::replaced_smallest;
  }
  solve();
  return outcome;
}

void OnlineHandEye::solve() {
  // Eq 4.17: weights from the current estimate, once there is one (before,
  // the null space is not yet one-dimensional and its vector means nothing).
  const bool have_rotation = status_.state != OnlineHandEyeState::collecting;
  const Quat R_previous = status_.T_base_lidar.rotation();
  std::vector<double> weights(pairs_.size(), 1.0);
  if (have_rotation) {
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
      weights[k] = huber_weight(hand_eye_residual_angle(pairs_[k], R_previous), config_.huber_delta_rad);
    }
  }
  const QuaternionSystem system = quaternion_system(pairs_, weights);  // eq 4.16
  const std::size_t seen = status_.pairs_seen;
  status_ = {};
  status_.pairs_seen = seen;
  status_.pairs_stored = pairs_.size();
  status_.pairs_translation = static_cast<std::size_t>(std::count(translation_valid_.begin(), translation_valid_.end(), true));
  for (int i = 0; i < 4; ++i) status_.singular_values[i] = system.singular(i);
  if (pairs_.size() < 2) return;
  if (system.singular(2) <= config_.rotation_threshold) {  // eq 4.17's test
    if (config_.planar_rotation && system.singular(1) > config_.rotation_threshold) solve_planar_rotation();
    return;
  }

  const Quat R(system.V(0, 3), system.V(1, 3), system.V(2, 3), system.V(3, 3));
  const Quat R_base_lidar = R.normalized();
  status_.state = OnlineHandEyeState::rotation_ready;
  status_.T_base_lidar = SE3(R_base_lidar, Vec3::Zero());
  double sum_sq = 0.0;
  for (const MotionPair& p : pairs_) sum_sq += std::pow(hand_eye_residual_angle(p, R_base_lidar), 2);
  status_.rotation_rms_rad = std::sqrt(sum_sq / static_cast<double>(pairs_.size()));
  solve_translation(weights, R_base_lidar);
}

void OnlineHandEye::solve_translation(std::span<const double> weights, const Quat& R_base_lidar) {
  const TranslationSystem ts = translation_system(pairs_, weights, translation_valid_, R_base_lidar);  // eq 4.18
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(ts.normal);
  const Vec3 lambda = eig.eigenvalues();  // ascending
  for (int i = 0; i < 3; ++i) status_.translation_eigenvalues[i] = lambda(i);
  if (status_.pairs_translation < config_.translation_min_pairs) return;
  if (!(lambda(2) > 0.0) || lambda(1) < config_.translation_min_ratio * lambda(2)) return;

  Vec3 t = Vec3::Zero();
  const int first_observable = lambda(0) < config_.planar_ratio * lambda(2) ? 1 : 0;
  if (first_observable == 1) {
    // Planar only when every stored pair's rotation says so; a weak direction
    // of the translation-valid subset alone (few pairs, close axes) waits for more pairs.
    const std::vector<bool> all(pairs_.size(), true);
    const Vec3 all_lambda =
        Eigen::SelfAdjointEigenSolver<Mat3>(translation_system(pairs_, weights, all, R_base_lidar).normal).eigenvalues();
    if (!(all_lambda(0) < config_.planar_ratio * all_lambda(2))) return;
  }
  for (int i = first_observable; i < 3; ++i) {
    t += eig.eigenvectors().col(i) * (eig.eigenvectors().col(i).dot(ts.rhs) / lambda(i));
  }
  status_.translation_std_m = translation_std(pairs_, weights, translation_valid_, SE3(R_base_lidar, t), eig, first_observable);
  if (!(status_.translation_std_m <= config_.translation_max_std_m)) return;
  if (first_observable == 1) {  // planar: the component along the common rotation axis stays 0 (t_z = 0)
    Vec3 axis = eig.eigenvectors().col(0);
    Eigen::Index largest = 0;
    axis.cwiseAbs().maxCoeff(&largest);
    if (axis(largest) < 0.0) axis = -axis;
    status_.planar_motion = true;
    status_.unobservable_axis_base = axis;
  }
  status_.state = OnlineHandEyeState::ready;
  status_.T_base_lidar = SE3(R_base_lidar, t);
}

void OnlineHandEye::solve_planar_rotation() {
  // Eq 3.8-3.12 over the translation-valid pairs: one rotation axis, so the
  // rotation about it and x, y come from the translations; t along it is 0.
  std::vector<MotionPair> valid;
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    if (translation_valid_[k]) valid.push_back(pairs_[k]);
  }
  if (pairs_.size() < config_.planar_min_pairs || valid.size() < std::max<std::size_t>(3, config_.translation_min_pairs)) return;
  const Vec3 axis = signed_common_axis(valid);
  const PlanarSolution planar = solve_planar(valid, axis);
  if (!(planar.condition >= config_.planar_min_condition)) return;
  const std::vector<double> ones(pairs_.size(), 1.0);
  const TranslationSystem ts = translation_system(pairs_, ones, translation_valid_, planar.T_a_b.rotation());
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(ts.normal);
  for (int i = 0; i < 3; ++i) status_.translation_eigenvalues[i] = eig.eigenvalues()(i);
  status_.translation_std_m = translation_std(pairs_, ones, translation_valid_, planar.T_a_b, eig, 1);
  status_.T_base_lidar = SE3(planar.T_a_b.rotation(), Vec3::Zero());
  double sum_sq = 0.0;
  for (const MotionPair& p : pairs_) sum_sq += std::pow(hand_eye_residual_angle(p, planar.T_a_b.rotation()), 2);
  status_.rotation_rms_rad = std::sqrt(sum_sq / static_cast<double>(pairs_.size()));
  if (!(status_.translation_std_m <= config_.translation_max_std_m)) return;
  status_.state = OnlineHandEyeState::ready;
  status_.T_base_lidar = planar.T_a_b;
  status_.planar_motion = true;
  status_.planar_rotation = true;
  status_.unobservable_axis_base = axis;
}

}  // namespace mlidar::calib
