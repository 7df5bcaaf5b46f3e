#include "mlidar/io/interrupt_cleanup.hpp"

#include <algorithm>
#include <set>

namespace mlidar::io {
namespace {

struct Registry {
  std::mutex mutex;
  std::set<std::filesystem::path> paths;
};

/// The one registry of the process (signals are process-wide).
Registry& registry() {
  static Registry instance;
  return instance;
}

}  // namespace

UnfinishedOutput::UnfinishedOutput(std::filesystem::path path) : path_(std::move(path)) {
  const std::lock_guard lock(registry().mutex);
  registry().paths.insert(path_);
}

UnfinishedOutput::~UnfinishedOutput() {
  const std::lock_guard lock(registry().mutex);
  registry().paths.erase(path_);
}

bool inside_unfinished_folder(const std::filesystem::path& path) {
  const std::filesystem::path absolute = std::filesystem::absolute(path).lexically_normal();
  const std::lock_guard lock(registry().mutex);
  for (const auto& folder : registry().paths) {
    const auto [end, rest] = std::mismatch(folder.begin(), folder.end(), absolute.begin(), absolute.end());
    if (end == folder.end() && rest != absolute.end()) return true;
  }
  return false;
}

std::unique_lock<std::mutex> lock_unfinished_outputs() { return std::unique_lock(registry().mutex); }

std::size_t remove_unfinished_outputs() {
  Registry& r = registry();
  r.mutex.lock();  // never released: the process exits after this
  std::size_t removed = 0;
  for (const auto& path : r.paths) {
    std::error_code ec;
    removed += std::filesystem::remove_all(path, ec) > 0 ? 1 : 0;
  }
  return removed;
}

}  // namespace mlidar::io
