#include "mlidar/slam/registration_trust.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "mlidar/core/median.hpp"

namespace mlidar::slam {

const char* trust_name(Trust trust) {
  switch (trust) {
    case Trust::kTrusted:
      return "trusted";
    case Trust::kResidual:
      return "residual";
    case Trust::kAmbiguous:
      return "ambiguous";
    case Trust::kDegenerate:
      return "degenerate";
    case Trust::kLost:
      return "lost";
  }
  return "?";
}

void ResidualHistory::add(double mean_residual_m) {
  if (capacity_ == 0 || !std::isfinite(mean_residual_m)) return;
  values_.push_back(mean_residual_m);
  if (values_.size() > capacity_) values_.pop_front();
}

double ResidualHistory::median_m() const {
  if (values_.empty()) return std::numeric_limits<double>::quiet_NaN();
  return median(std::vector<double>(values_.begin(), values_.end()));
}

bool TrustRule::acceptable(const RegistrationResult& r) const {
  if (!(r.mean_residual_m <= config.max_mean_residual_m)) return false;
  if (r.match_ratio() >= config.min_match_ratio) return true;
  return first_sweep_map && r.match_ratio() >= config.first_match_ratio && r.converged && !r.degenerate &&
         r.mean_residual_m <= config.first_max_residual_m;
}

double TrustRule::trusted_limit_m() const {
  if (!std::isfinite(recent_median_m)) return config.history_free_max_residual_m;
  return std::max(config.residual_floor_m, config.residual_ratio * recent_median_m);
}

bool TrustRule::trusted(const RegistrationResult& r) const { return acceptable(r) && r.mean_residual_m <= trusted_limit_m(); }

namespace {

/// True when b lies farther than `translation_m` from a or is turned more than `rotation_deg` from it.
bool farther_than(const SE3& a, const SE3& b, double translation_m, double rotation_deg) {
  const SE3 between = a.inverse() * b;
  return between.translation().norm() > translation_m || so3_log(between.rotation()).norm() * 180.0 / std::numbers::pi > rotation_deg;
}

}  // namespace

Choice choose_registration(std::span<const RegistrationResult> candidates, const TrustRule& rule) {
  if (candidates.empty()) throw std::invalid_argument("choose_registration: no candidates");
  Choice choice;
  bool any = false;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!rule.acceptable(candidates[i])) continue;
    if (!any || candidates[i].mean_residual_m < candidates[choice.best].mean_residual_m) choice.best = i;
    any = true;
  }
  if (!any) return choice;
  const RegistrationResult& best = candidates[choice.best];
  choice.trust = rule.trusted(best) ? Trust::kTrusted : Trust::kResidual;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (i == choice.best || !rule.acceptable(candidates[i])) continue;
    if (candidates[i].mean_residual_m > rule.config.ambiguity_ratio * best.mean_residual_m) continue;
    if (!farther_than(candidates[i].T_world_base, best.T_world_base, rule.config.distinct_translation_m, rule.config.distinct_rotation_deg))
      continue;
    choice.trust = Trust::kAmbiguous;
    choice.rival = i;
    break;
  }
  return choice;
}

std::vector<SE3> refinable_poses(std::span<const RegistrationResult> coarse, double max_mean_residual_m) {
  if (coarse.empty()) throw std::invalid_argument("refinable_poses: no registrations");
  const auto tightest = std::min_element(coarse.begin(), coarse.end(), [](const RegistrationResult& a, const RegistrationResult& b) {
    return a.mean_residual_m < b.mean_residual_m;
  });
  std::vector<SE3> kept;
  for (auto r = coarse.begin(); r != coarse.end(); ++r)
    if (r == tightest || !r->converged || r->mean_residual_m <= max_mean_residual_m) kept.push_back(r->T_world_base);
  return kept;
}

std::vector<SE3> distinct_poses(std::span<const SE3> poses, double translation_m, double rotation_deg) {
  std::vector<SE3> kept;
  for (const SE3& pose : poses) {
    const bool seen = std::any_of(kept.begin(), kept.end(),
                                  [&](const SE3& k) { return !farther_than(k, pose, translation_m, rotation_deg); });
    if (!seen) kept.push_back(pose);
  }
  return kept;
}

Trust judge_degenerate_correction(Trust trust, const RegistrationResult& r, const SE3& prediction, const TrustConfig& config) {
  if (trust != Trust::kTrusted || !r.degenerate) return trust;
  return farther_than(prediction, r.T_world_base, config.degenerate_max_correction_m, config.degenerate_max_correction_deg)
             ? Trust::kDegenerate
             : trust;
}

}  // namespace mlidar::slam
