#include "mlidar/io/atomic_file.hpp"

#include <fstream>
#include <random>
#include <string>

#include "mlidar/core/error.hpp"

namespace mlidar::io {
namespace {
std::filesystem::path temporary_name(const std::filesystem::path& path) {
  std::random_device device;
  const auto tag = std::to_string(device());
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + tag;
  return tmp;
}
}  // namespace

void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write) {
  const std::filesystem::path tmp = temporary_name(path);
  try {
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) throw OutputError(path.string() + ": cannot create a file in this folder (check that it exists and is writable)");
      write(out);
      out.flush();
      if (!out) throw OutputError(path.string() + ": write failed (disk full?)");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw OutputError(path.string() + ": cannot rename the finished file into place: " + ec.message());
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
}

}  // namespace mlidar::io
