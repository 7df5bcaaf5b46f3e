#include "mlidar/calib/online_hand_eye.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "mlidar/calib/hand_eye_linear.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

void validate(const OnlineHandEyeConfig& c) {
  const bool ok = c.max_constraints >= 2 && c.rotation_threshold > 0.0 && c.huber_delta_rad > 0.0 && c.planar_ratio > 0.0 &&
                  c.planar_ratio < 1.0 && c.translation_min_ratio > 0.0 && c.translation_min_ratio < c.planar_ratio;
  if (!ok) {
    throw std::invalid_argument(
        "OnlineHandEyeConfig: max_constraints >= 2, thresholds > 0, 0 < translation_min_ratio < planar_ratio < 1");
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

/// Eq 4.18 normal equations, rows (R_A - I) t = R t_B - t_A scaled by w_k like eq 4.16's.
TranslationSystem translation_system(std::span<const MotionPair> pairs, std::span<const double> weights,
                                     const Quat& R_base_lidar) {
  TranslationSystem s;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const double w2 = weights[k] * weights[k];
    const Mat3 M = pairs[k].A.rotation_matrix() - Mat3::Identity();
    const Vec3 b = R_base_lidar * pairs[k].B.translation() - pairs[k].A.translation();
    s.normal += w2 * M.transpose() * M;
    s.rhs += w2 * M.transpose() * b;
  }
  return s;
}

}  // namespace

std::string_view to_string(OnlineHandEyeState state) {
  switch (state) {
    case OnlineHandEyeState::collecting: return "collecting";
    case OnlineHandEyeState::rotation_ready: return "rotation_ready";
    case OnlineHandEyeState::ready: return "ready";
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
  status_ = {};
}

PairOutcome OnlineHandEye::add(const MotionPair& pair) {
  ++status_.pairs_seen;
  if (!finite(pair.A) || !finite(pair.B)) return PairOutcome::rejected_invalid;
  const double angle = pair_rotation_angle(pair);
  PairOutcome outcome = PairOutcome::stored;
  if (pairs_.size() < config_.max_constraints) {
    pairs_.push_back(pair);
    rotation_angles_.push_back(angle);
  } else {
    // Sec. 4.6.2.1: a bounded priority store; constraints with small rotation are removed.
    const auto smallest = std::min_element(rotation_angles_.begin(), rotation_angles_.end());
    if (angle <= *smallest) return PairOutcome::dropped_small;
    const auto index = static_cast<std::size_t>(std::distance(rotation_angles_.begin(), smallest));
    pairs_[index] = pair;
    rotation_angles_[index] = angle;
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
  for (int i = 0; i < 4; ++i) status_.singular_values[i] = system.singular(i);
  if (pairs_.size() < 2 || system.singular(2) <= config_.rotation_threshold) return;  // eq 4.17's test

  const Quat R(system.V(0, 3), system.V(1, 3), system.V(2, 3), system.V(3, 3));
  const Quat R_base_lidar = R.normalized();
  status_.state = OnlineHandEyeState::rotation_ready;
  status_.T_base_lidar = SE3(R_base_lidar, Vec3::Zero());
  double sum_sq = 0.0;
  for (const MotionPair& p : pairs_) sum_sq += std::pow(hand_eye_residual_angle(p, R_base_lidar), 2);
  status_.rotation_rms_rad = std::sqrt(sum_sq / static_cast<double>(pairs_.size()));

  const TranslationSystem ts = translation_system(pairs_, weights, R_base_lidar);  // eq 4.18
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(ts.normal);
  const Vec3 lambda = eig.eigenvalues();  // ascending
  for (int i = 0; i < 3; ++i) status_.translation_eigenvalues[i] = lambda(i);
  if (!(lambda(2) > 0.0) || lambda(1) < config_.translation_min_ratio * lambda(2)) return;

  Vec3 t = Vec3::Zero();
  const int first_observable = lambda(0) < config_.planar_ratio * lambda(2) ? 1 : 0;
  for (int i = first_observable; i < 3; ++i) {
    t += eig.eigenvectors().col(i) * (eig.eigenvectors().col(i).dot(ts.rhs) / lambda(i));
  }
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

}  // namespace mlidar::calib
