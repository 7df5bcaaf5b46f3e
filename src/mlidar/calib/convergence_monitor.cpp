#include "mlidar/calib/convergence_monitor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/median.hpp"
#include "mlidar/core/rotation_average.hpp"

namespace mlidar::calib {
namespace {

constexpr std::array<const char*, 6> kAxisNames = {"translation x",    "translation y",    "translation z",
                                                   "rotation about x", "rotation about y", "rotation about z"};
constexpr double kSingleAxisShare = 0.9;  ///< squared share for a single-axis name
constexpr double kListedShare = 0.1;      ///< squared share for a component to be listed

/// Karcher (geodesic L2) mean: R <- Exp(mean_i Log(R_i R^-1)) R from the chordal mean.
Quat karcher_mean(std::span<const Quat> rotations) {
  Quat mean = chordal_mean(rotations);
  for (int iteration = 0; iteration < 50; ++iteration) {
    Vec3 step = Vec3::Zero();
    for (const Quat& R : rotations) step += so3_log(R * mean.conjugate());
    step /= static_cast<double>(rotations.size());
    mean = (so3_exp(step) * mean).normalized();
    if (step.norm() < 1e-15) break;
  }
  return mean;
}

bool finite(const SE3& T) { return T.rotation().coeffs().allFinite() && T.translation().allFinite(); }

constexpr double kMadToSigma = 1.4826;  ///< MAD of a normal distribution times this is its sigma
/// Robust sigma floor of the accepted estimates, [t m, r rad]: agreeing windows are never trimmed for mm scatter.
Vec6 robust_sigma_floor() { return (Vec6() << Vec3::Constant(0.002), Vec3::Constant(deg_to_rad(0.02))).finished(); }

}  // namespace

std::string describe_direction(const Vec6& direction) {
  const Vec6 unit = direction.normalized();
  std::array<int, 6> order{};
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(unit(a)) > std::abs(unit(b)); });
  if (unit(order[0]) * unit(order[0]) >= kSingleAxisShare) return kAxisNames[order[0]];
  const double sign = unit(order[0]) < 0.0 ? -1.0 : 1.0;  // largest component positive
  std::string words;
  for (const int axis : order) {
    const double c = sign * unit(axis);
    if (c * c < kListedShare) break;
    char term[64];
    if (words.empty()) {
      std::snprintf(term, sizeof term, "%.2f %s", c, kAxisNames[axis]);
    } else {
      std::snprintf(term, sizeof term, " %c %.2f %s", c < 0.0 ? '-' : '+', std::abs(c), kAxisNames[axis]);
    }
    words += term;
  }
  return words;
}

std::vector<WeakDirection> weak_directions(const Mat6& information, double threshold) {
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(0.5 * (information + information.transpose()));
  std::vector<WeakDirection> weak;
  for (int i = 0; i < 6 && eig.eigenvalues()(i) < threshold; ++i) {  // ascending
    Vec6 v = eig.eigenvectors().col(i);
    Eigen::Index largest = 0;
    v.cwiseAbs().maxCoeff(&largest);
    if (v(largest) < 0.0) v = -v;
    weak.push_back({eig.eigenvalues()(i), v, describe_direction(v)});
  }
  return weak;
}

ExtrinsicMean extrinsic_mean(std::span<const SE3> samples) {
  if (samples.empty()) throw std::invalid_argument("extrinsic_mean: no samples");
  std::vector<Quat> rotations;
  Vec3 t_mean = Vec3::Zero();
  for (const SE3& T : samples) {
    rotations.push_back(T.rotation());
    t_mean += T.translation();
  }
  t_mean /= static_cast<double>(samples.size());
  ExtrinsicMean result{SE3(karcher_mean(rotations), t_mean), Mat6::Zero(), {}};
  if (samples.size() < 2) return result;
  for (const SE3& T : samples) {
    Vec6 d;
    d << T.translation() - t_mean, so3_log(T.rotation() * result.mean.rotation().conjugate());
    result.covariance += d * d.transpose();
    result.local_deviations.push_back((Vec6() << d.head<3>(), so3_log(result.mean.rotation().conjugate() * T.rotation())).finished());
  }
  result.covariance /= static_cast<double>(samples.size() - 1);
  return result;
}

std::vector<std::size_t> robust_inliers(std::span<const Vec6> deviations, double max_mads, const Vec6& sigma_floor) {
  std::vector<std::size_t> inliers(deviations.size());
  std::iota(inliers.begin(), inliers.end(), std::size_t{0});
  if (!(max_mads > 0.0) || deviations.empty()) return inliers;
  Vec6 centre, bound;
  for (int axis = 0; axis < 6; ++axis) {
    std::vector<double> values;
    for (const Vec6& d : deviations) values.push_back(d(axis));
    centre(axis) = median(values);
    for (double& v : values) v = std::abs(v - centre(axis));
    bound(axis) = max_mads * std::max(kMadToSigma * median(values), sigma_floor(axis));
  }
  std::erase_if(inliers, [&](std::size_t i) { return ((deviations[i] - centre).cwiseAbs().array() > bound.array()).any(); });
  return inliers;
}

std::string_view to_string(CalibrationMode mode) {
  switch (mode) {
    case CalibrationMode::calibrating:
      return "calibrating";
    case CalibrationMode::converged:
      return "converged";
  }
  return "unknown";
}

ConvergenceMonitor::ConvergenceMonitor(std::vector<SE3> initial, ConvergenceConfig config) : config_(config) {
  if (initial.empty() || config_.accepted_needed < 2 || !(config_.lambda_calib > 0.0) || !(config_.min_autocorrelation_time >= 1.0)) {
    throw std::invalid_argument(
        "ConvergenceMonitor: needs >= 1 LiDAR, accepted_needed >= 2, lambda_calib > 0, min_autocorrelation_time >= 1");
  }
  for (const SE3& T : initial) {
    LidarCalibrationState state;
    state.T_base_lidar = T;
    lidars_.push_back(std::move(state));
  }
}

WindowVerdict ConvergenceMonitor::add_window(std::size_t lidar, const SE3& T_base_lidar, const Mat6& information, double residual_variance,
                                             bool settled) {
  LidarCalibrationState& state = lidars_.at(lidar);
  WindowVerdict verdict;
  if (state.mode == CalibrationMode::converged) return verdict;  // line 2: calibration has stopped
  ++state.windows;
  if (!finite(T_base_lidar) || !information.allFinite()) {
    state.last_lambda_min = 0.0;
    return verdict;
  }
  // Lines 3-4: the degeneracy factor.
  state.weak = weak_directions(information, config_.lambda_calib);
  verdict.lambda_min =
      Eigen::SelfAdjointEigenSolver<Mat6>(0.5 * (information + information.transpose()), Eigen::EigenvaluesOnly).eigenvalues()(0);
  state.last_lambda_min = verdict.lambda_min;
  verdict.constrained = verdict.lambda_min > config_.lambda_calib;
  if (!verdict.constrained || !settled) return verdict;
  // Lines 5-7: accept.
  verdict.accepted = true;
  state.T_base_lidar = T_base_lidar;
  state.accepted.push_back(T_base_lidar);
  if (residual_variance > 0.0 && std::isfinite(residual_variance))
    state.accepted_covariances.push_back(local_covariance_from_left_information(T_base_lidar, information, residual_variance));
  if (state.accepted.size() < config_.accepted_needed) return verdict;
  // Lines 8-11: mean, covariance, stop, over the estimates that agree with the
  // median (when they are at least half). The windows' term only when every accepted window gave one.
  const bool all_windows = state.accepted_covariances.size() == state.accepted.size();
  std::vector<SE3> kept = state.accepted;
  std::vector<Mat6> kept_covariances = all_windows ? state.accepted_covariances : std::vector<Mat6>{};
  const std::vector<std::size_t> inliers =
      robust_inliers(extrinsic_mean(state.accepted).local_deviations, config_.outlier_mads, robust_sigma_floor());
  if (inliers.size() < state.accepted.size() && 2 * inliers.size() >= state.accepted.size()) {
    kept.clear();
    kept_covariances.clear();
    for (const std::size_t i : inliers) {
      kept.push_back(state.accepted[i]);
      if (all_windows) kept_covariances.push_back(state.accepted_covariances[i]);
    }
    state.outliers = state.accepted.size() - inliers.size();
  }
  const ExtrinsicMean mean = extrinsic_mean(kept);
  state.T_base_lidar = mean.mean;
  state.covariance_parts =
      calibration_covariance(mean.local_deviations, all_windows ? std::span<const Mat6>(kept_covariances) : std::span<const Mat6>(),
                             config_.min_autocorrelation_time);
  Vec6 bias_sd;
  bias_sd << Vec3::Constant(config_.bias_translation_sd_m), Vec3::Constant(deg_to_rad(config_.bias_rotation_sd_deg));
  state.covariance_parts.bias = bias_sd.cwiseAbs2().asDiagonal();
  state.covariance_parts.total += state.covariance_parts.bias;
  state.covariance = state.covariance_parts.total;
  state.mode = CalibrationMode::converged;
  verdict.converged_now = true;
  return verdict;
}

void ConvergenceMonitor::restart(std::size_t lidar) {
  LidarCalibrationState& state = lidars_.at(lidar);
  state.mode = CalibrationMode::calibrating;
  state.accepted.clear();
  state.accepted_covariances.clear();
  state.covariance = Mat6::Zero();
  state.covariance_parts = {};
  state.weak.clear();
  state.outliers = 0;
  ++state.restarts;
}

bool ConvergenceMonitor::all_converged() const {
  return std::all_of(lidars_.begin(), lidars_.end(), [](const LidarCalibrationState& s) { return s.mode == CalibrationMode::converged; });
}

}  // namespace mlidar::calib
