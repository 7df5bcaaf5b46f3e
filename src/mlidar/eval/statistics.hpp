#pragma once
// Summary statistics of an error sequence, as evo reports them
// (evo/core/metrics.py get_all_statistics: std is the population std, ddof = 0).
#include <cstddef>
#include <vector>

namespace mlidar::eval {

struct ErrorStats {
  std::size_t count = 0;  ///< 0: no values, every other field is NaN
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;  ///< middle value, mean of the two middle values for even counts
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
};

ErrorStats summarize(std::vector<double> values);

}  // namespace mlidar::eval
