#include "mlidar/eval/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mlidar::eval {

ErrorStats summarize(std::vector<double> values) {
  ErrorStats stats;
  stats.count = values.size();
  if (values.empty()) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    stats.rmse = stats.mean = stats.median = stats.std = stats.min = stats.max = nan;
    return stats;
  }
  const double n = static_cast<double>(values.size());
  double sum = 0.0;
  double sum_sq = 0.0;
  for (const double value : values) {
    sum += value;
    sum_sq += value * value;
  }
  stats.mean = sum / n;
  stats.rmse = std::sqrt(sum_sq / n);
  double centred_sq = 0.0;  // second pass: no cancellation in the variance
  for (const double value : values) centred_sq += (value - stats.mean) * (value - stats.mean);
  stats.std = std::sqrt(centred_sq / n);
  const auto [min_it, max_it] = std::minmax_element(values.begin(), values.end());
  stats.min = *min_it;
  stats.max = *max_it;
  const std::size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle), values.end());
  stats.median = values[middle];
  if (values.size() % 2 == 0) {
    const double below = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle));
    stats.median = 0.5 * (stats.median + below);
  }
  return stats;
}

}  // namespace mlidar::eval
