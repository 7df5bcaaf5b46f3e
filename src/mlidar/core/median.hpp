#pragma once
// Medians of small samples (residual histories, per-axis estimates, gaps
// between stamps). Both take the values by copy and reorder the copy.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace mlidar {

/// The middle value; for an even count the mean of the two middle ones. `values` must not be empty.
inline double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(values.begin(), middle));
}

/// The value at index size / 2 of the sorted values (for an even count the upper
/// of the two middle ones: always one of the values). `values` must not be empty.
inline double upper_median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace mlidar
