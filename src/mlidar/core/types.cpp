#include "mlidar/core/types.hpp"

namespace mlidar {

bool Scan::is_consistent() const {
  const std::size_t n = points.size();
  return (intensity.empty() || intensity.size() == n) && (ring.empty() || ring.size() == n) && (time.empty() || time.size() == n);
}

}  // namespace mlidar
