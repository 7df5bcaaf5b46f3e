#include "mlidar/core/fixed_decimals.hpp"

#include <cmath>
#include <cstdio>

namespace mlidar {

std::string fixed(double value, int digits) {
  if (!std::isfinite(value)) return "-";
  char buffer[352];  // enough for any finite double in %f
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

}  // namespace mlidar
