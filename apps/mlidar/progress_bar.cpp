#include "apps/mlidar/progress_bar.hpp"

#include <cstdio>
#include <string>

#include <unistd.h>

namespace mlidar::cli {

std::function<void(int, int)> terminal_progress_bar() {
  if (isatty(fileno(stderr)) == 0) return {};
  return [](int done, int total) {
    constexpr int kWidth = 40;
    const int filled = total > 0 ? kWidth * done / total : kWidth;
    std::fprintf(stderr, "\r[%s%s] %d/%d frames", std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), ' ').c_str(), done, total);
    if (done == total) std::fputc('\n', stderr);
  };
}

}  // namespace mlidar::cli
