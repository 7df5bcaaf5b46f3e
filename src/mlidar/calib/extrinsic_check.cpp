#include "mlidar/calib/extrinsic_check.hpp"

#include <cmath>
#include <stdexcept>

#include "mlidar/core/fixed_decimals.hpp"
#include "mlidar/core/median.hpp"

namespace mlidar::calib {
namespace {

bool valid(double residual) { return std::isfinite(residual) && residual > 1e-12; }

}  // namespace

ExtrinsicCheck::ExtrinsicCheck(std::size_t lidar_count, ExtrinsicCheckConfig config) : config_(config), lidars_(lidar_count) {
  if (lidar_count == 0 || config_.frames == 0 || !(config_.residual_ratio >= 0.0))
    throw std::invalid_argument("ExtrinsicCheck: needs >= 1 LiDAR, frames >= 1 and residual_ratio >= 0");
}

void ExtrinsicCheck::reset(std::size_t lidar) { lidars_.at(lidar) = LidarState{}; }

std::optional<double> ExtrinsicCheck::median_ratio(std::size_t lidar) const {
  const LidarState& state = lidars_.at(lidar);
  if (state.ratios.size() < config_.frames) return std::nullopt;
  return median(std::vector<double>(state.ratios.begin(), state.ratios.end()));
}

std::vector<std::size_t> ExtrinsicCheck::update(std::span<const double> mean_residual_m, const std::vector<bool>& checked) {
  if (mean_residual_m.size() != lidars_.size() || checked.size() != lidars_.size())
    throw std::invalid_argument("ExtrinsicCheck::update: one residual and one flag per LiDAR");
  std::vector<std::size_t> fired;
  if (config_.residual_ratio == 0.0 || !valid(mean_residual_m[0])) return fired;
  for (std::size_t j = 1; j < lidars_.size(); ++j) {
    LidarState& state = lidars_[j];
    if (!checked[j] || !valid(mean_residual_m[j])) continue;
    state.ratios.push_back(mean_residual_m[j] / mean_residual_m[0]);
    if (state.ratios.size() > config_.frames) state.ratios.pop_front();
    const std::optional<double> ratio = median_ratio(j);
    if (!state.disagreed && ratio && *ratio > config_.residual_ratio) {
      state.disagreed = true;
      fired.push_back(j);
    }
  }
  return fired;
}

std::string describe(const DisagreementEvidence& evidence) {
  const std::string at = "at frame " + std::to_string(evidence.frame);
  if (evidence.frames_lost)
    return "the frames after the first could not be registered with the given extrinsics (lost from the start): any of them "
           "may be wrong";
  if (evidence.map_ratio > 0.0)
    return at + " its points in the map lay " + fixed(evidence.map_ratio, 1) +
           "x farther from the other LiDARs' surfaces than from its own; right extrinsics stay near 1";
  return at + " its residual was " + fixed(evidence.residual_ratio, 1) + "x " + evidence.reference +
         "'s, the median of the last extrinsic_check.frames frames; right extrinsics stay near 1";
}

}  // namespace mlidar::calib
