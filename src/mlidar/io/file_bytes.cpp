#include "mlidar/io/file_bytes.hpp"

#include <fstream>
#include <system_error>

#include "mlidar/core/error.hpp"

namespace mlidar::io {

std::vector<std::byte> read_file_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(path.string(), "", "no such file (check the path)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "", "cannot open for reading (check permissions)");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path.string(), "", "cannot read its size: " + ec.message());
  std::vector<std::byte> bytes(size);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    throw InputError(path.string(), "", "read ended early (file changed or unreadable)");
  }
  return bytes;
}

std::string read_file_text(const std::filesystem::path& path) {
  const auto bytes = read_file_bytes(path);
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

}  // namespace mlidar::io
