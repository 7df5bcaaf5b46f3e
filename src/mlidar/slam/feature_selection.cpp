#include "mlidar/slam/feature_selection.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace mlidar::slam {
namespace {

/// A draw in [0, n) from the engine's 64 bits (bias below n / 2^64; the
/// standard distributions give different draws in different libraries).
std::size_t draw_below(std::mt19937_64& engine, std::size_t n) { return static_cast<std::size_t>(engine() % n); }

/// The gain log det(Lambda + U U^T) - log det(Lambda) = log det(I + V^T V),
/// V = L^-1 U (matrix determinant lemma), with L the Cholesky factor of Lambda.
double log_det_gain(const Eigen::LLT<Mat6>& factor, const FeatureInformation& feature) {
  if (feature.rank == 1) {
    const Vec6 v = factor.matrixL().solve(feature.rows.col(0));
    return std::log1p(v.squaredNorm());
  }
  const Eigen::Matrix<double, 6, 2> v = factor.matrixL().solve(feature.rows);
  const double a = v.col(0).squaredNorm(), b = v.col(0).dot(v.col(1)), c = v.col(1).squaredNorm();
  return std::log((1.0 + a) * (1.0 + c) - b * b);
}

void add_information(const FeatureInformation& feature, Mat6& information) {
  const auto u = feature.rows.leftCols(feature.rank);
  information.noalias() += u * u.transpose();
}

double log_det_of(const Eigen::LLT<Mat6>& factor) { return 2.0 * factor.matrixLLT().diagonal().array().log().sum(); }

/// delta I plus the features' information.
Mat6 total_information(std::span<const FeatureInformation> features) {
  Mat6 total = kPriorInformation * Mat6::Identity();
  for (const FeatureInformation& f : features) add_information(f, total);
  return total;
}

/// Every feature that has a correspondence (a budget of at least all of them).
SelectionResult every_matched(std::size_t count, const InformationSource& information) {
  SelectionResult result;
  Mat6 total = kPriorInformation * Mat6::Identity();
  for (std::uint32_t i = 0; i < count; ++i) {
    const FeatureInformation* f = information(i);
    if (f == nullptr) continue;
    result.chosen.push_back(i);
    add_information(*f, total);
  }
  result.visited = count;
  result.matched = result.chosen.size();
  result.log_det = log_det_of(Eigen::LLT<Mat6>(total));
  return result;
}

}  // namespace

const char* selection_method_name(SelectionMethod method) {
  switch (method) {
    case SelectionMethod::kNone:
      return "none";
    case SelectionMethod::kRandom:
      return "random";
    case SelectionMethod::kGreedy:
      return "greedy";
  }
  return "?";
}

Mat6 FeatureInformation::information() const {
  Mat6 out = Mat6::Zero();
  add_information(*this, out);
  return out;
}

double log_det_information(std::span<const FeatureInformation> features) {
  return log_det_of(Eigen::LLT<Mat6>(total_information(features)));
}

Degeneracy degeneracy_of(std::span<const FeatureInformation> features) {
  const Mat6 total = total_information(features);
  const Vec3 spread = Eigen::SelfAdjointEigenSolver<Mat3>(total.topLeftCorner<3, 3>()).eigenvalues();
  return {log_det_of(Eigen::LLT<Mat6>(total)), spread(2) > 0.0 ? spread(0) / spread(2) : 0.0};
}

bool degenerate_scene(const Degeneracy& full_set, const SelectionConfig& config) {
  return config.adaptive && full_set.translation_observability < config.degeneracy_threshold;
}

std::size_t selection_budget(std::size_t available, bool degenerate, const SelectionConfig& config) {
  // Sec 5.4.4: a degenerate scene keeps most of its features.
  const double share = degenerate ? config.degenerate_ratio : config.ratio;
  const auto budget = static_cast<std::size_t>(std::ceil(share * static_cast<double>(available)));
  return std::min(available, std::max(budget, config.min_features));
}

SelectionResult select_greedy(std::size_t count, std::size_t budget, const InformationSource& information, const SelectionConfig& config) {
  if (budget >= count) return every_matched(count, information);
  const auto start = std::chrono::steady_clock::now();
  std::mt19937_64 engine(config.seed);
  // Algorithm 2, line 3: |R| = N / M log(1 / epsilon).
  const auto sample_size = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::ceil(static_cast<double>(count) / static_cast<double>(budget) * std::log(1.0 / config.epsilon))));
  std::vector<std::uint32_t> remaining(count);
  std::iota(remaining.begin(), remaining.end(), 0U);
  std::vector<bool> visited(count, false);
  SelectionResult result;
  result.chosen.reserve(budget);
  Mat6 total = kPriorInformation * Mat6::Identity();
  Eigen::LLT<Mat6> factor(total);
  while (result.chosen.size() < budget && !remaining.empty()) {
    if (config.time_budget_ms > 0.0 &&
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() > config.time_budget_ms) {
      result.stopped_by_time = true;
      break;
    }
    // The random subset R: a partial Fisher-Yates shuffle moves it to the front of `remaining`.
    std::size_t drawn = 0, best = 0;
    double best_gain = -1.0;
    while (drawn < sample_size && drawn < remaining.size()) {
      std::swap(remaining[drawn], remaining[drawn + draw_below(engine, remaining.size() - drawn)]);
      const std::uint32_t candidate = remaining[drawn];
      if (!visited[candidate]) {
        visited[candidate] = true;
        ++result.visited;
      }
      const FeatureInformation* f = information(candidate);  // lines 5-8: searched on first use
      if (f == nullptr) {                                    // line 10: no correspondence, out of F
        remaining[drawn] = remaining.back();
        remaining.pop_back();
        continue;
      }
      const double gain = log_det_gain(factor, *f);  // line 11
      if (gain > best_gain) {
        best_gain = gain;
        best = drawn;
      }
      ++drawn;
    }
    if (drawn == 0) break;
    // Lines 12-13: Lambda(S) += Lambda_i*, S += {i*}.
    const std::uint32_t chosen = remaining[best];
    remaining[best] = remaining.back();
    remaining.pop_back();
    result.chosen.push_back(chosen);
    add_information(*information(chosen), total);
    factor.compute(total);
  }
  result.matched = result.visited - (count - remaining.size() - result.chosen.size());
  std::sort(result.chosen.begin(), result.chosen.end());
  result.log_det = log_det_of(factor);
  return result;
}

SelectionResult select_random(std::size_t count, std::size_t budget, const InformationSource& information, std::uint64_t seed) {
  if (budget >= count) return every_matched(count, information);
  std::mt19937_64 engine(seed);
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0U);
  SelectionResult result;
  Mat6 total = kPriorInformation * Mat6::Identity();
  for (std::size_t j = 0; j < count && result.chosen.size() < budget; ++j) {
    std::swap(order[j], order[j + draw_below(engine, count - j)]);
    ++result.visited;
    const FeatureInformation* f = information(order[j]);
    if (f == nullptr) continue;
    result.chosen.push_back(order[j]);
    add_information(*f, total);
  }
  result.matched = result.chosen.size();
  std::sort(result.chosen.begin(), result.chosen.end());
  result.log_det = log_det_of(Eigen::LLT<Mat6>(total));
  return result;
}

}  // namespace mlidar::slam
