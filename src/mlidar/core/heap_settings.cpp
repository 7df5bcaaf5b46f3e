#include "mlidar/core/heap_settings.hpp"

#include <malloc.h>

namespace mlidar {

void keep_large_buffers_in_the_heap() {
  constexpr int kBytes = 256 << 20;
  mallopt(M_MMAP_THRESHOLD, kBytes);
  mallopt(M_TRIM_THRESHOLD, kBytes);
}

}  // namespace mlidar
