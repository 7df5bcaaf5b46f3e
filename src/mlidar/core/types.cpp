#include "mlidar/core/types.hpp"

namespace mlidar {

bool Scan::is_consistent() const {
  const std::size_t n = points.size();
  return (intensity.empty() || intensity.size() == n) && (ring.empty() || ring.size() == n) &&
         (time.empty() || time.size() == n);
}

int Rig::find(const std::string& name) const {
  for (std::size_t i = 0; i < lidars.size(); ++i) {
    if (lidars[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace mlidar
