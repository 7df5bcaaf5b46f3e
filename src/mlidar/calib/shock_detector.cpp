#include "mlidar/calib/shock_detector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mlidar/core/median.hpp"

namespace mlidar::calib {
namespace {

constexpr double kMadToSigma = 1.4826;  ///< MAD of a Gaussian times this is its sigma
constexpr double kTinyResidual = 1e-12;

bool valid(double residual) { return std::isfinite(residual) && residual > kTinyResidual; }

}  // namespace

ShockDetector::ShockDetector(std::size_t lidar_count, ShockDetectorConfig config) : config_(config), lidars_(lidar_count) {
  const bool ok = lidar_count > 0 && config_.min_history >= 3 && config_.history >= config_.min_history && config_.threshold_mads > 0.0 &&
                  config_.min_relative_jump > 0.0 && config_.consecutive >= 1;
  if (!ok) {
    throw std::invalid_argument("ShockDetector: needs >= 1 LiDAR, 3 <= min_history <= history, thresholds > 0, consecutive >= 1");
  }
}

void ShockDetector::reset(std::size_t lidar) {
  ShockLidarState& state = lidars_.at(lidar);
  state.baseline.clear();
  state.high_run = 0;
  state.last_limit = 0.0;
}

bool ShockDetector::decide(ShockLidarState& state, double score) const {
  state.last_score = score;
  if (state.baseline.size() >= config_.min_history) {
    const std::vector<double> baseline(state.baseline.begin(), state.baseline.end());
    const double m = median(baseline);
    std::vector<double> deviations;
    for (const double b : baseline) deviations.push_back(std::abs(b - m));
    const double sigma = kMadToSigma * median(deviations);
    state.last_limit = m + std::max(config_.threshold_mads * sigma, std::log1p(config_.min_relative_jump));
    if (score > state.last_limit) return ++state.high_run >= config_.consecutive;
  }
  state.high_run = 0;
  state.baseline.push_back(score);
  if (state.baseline.size() > config_.history) state.baseline.pop_front();
  return false;
}

std::vector<std::size_t> ShockDetector::update(std::span<const double> mean_residual_m) {
  if (mean_residual_m.size() != lidars_.size()) throw std::invalid_argument("ShockDetector::update: one residual per LiDAR");
  std::vector<std::size_t> fired;
  for (std::size_t i = 0; i < lidars_.size(); ++i) {
    if (!valid(mean_residual_m[i])) continue;
    double score = mean_residual_m[i];
    if (config_.relative_to_others) {
      std::vector<double> others;
      for (std::size_t j = 0; j < lidars_.size(); ++j) {
        if (j != i && valid(mean_residual_m[j])) others.push_back(mean_residual_m[j]);
      }
      if (lidars_.size() > 1) {
        if (others.empty()) continue;  // nothing to compare with this frame
        score /= median(others);
      }
    }
    if (decide(lidars_[i], std::log(score))) {
      fired.push_back(i);
      ++lidars_[i].triggers;
      reset(i);
    }
  }
  return fired;
}

}  // namespace mlidar::calib
