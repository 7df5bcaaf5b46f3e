#include "mlidar/io/file_bytes.hpp"

#include <fstream>
#include <iostream>
#include <iterator>
#include <system_error>

#include "mlidar/core/error.hpp"

namespace mlidar::io {
namespace {

std::vector<std::byte> read_to_end(std::istream& in, const std::string& name) {
  std::vector<std::byte> bytes;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    const auto* begin = reinterpret_cast<const std::byte*>(chunk);
    bytes.insert(bytes.end(), begin, begin + in.gcount());
  }
  if (in.bad()) throw InputError(name, "", "read failed");
  return bytes;
}

}  // namespace

bool is_stream_path(const std::filesystem::path& path) {
  std::error_code ec;
  return path == "-" ||
         (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec) && !std::filesystem::is_directory(path, ec));
}

std::vector<std::byte> read_file_bytes(const std::filesystem::path& path) {
  if (path == "-") {
    std::cin.clear();
    return read_to_end(std::cin, "- (standard input)");
  }
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw InputError(path.string(), "", "no such file (check the path)");
  if (std::filesystem::is_directory(status)) throw InputError(path.string(), "", "is a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "", "cannot open for reading (check permissions)");
  if (!std::filesystem::is_regular_file(status)) return read_to_end(in, path.string());  // a pipe: read it once, to its end
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
