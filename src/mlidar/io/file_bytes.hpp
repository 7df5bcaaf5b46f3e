#pragma once
// Reads a whole file into memory, with errors that name the file.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace mlidar::io {

/// Throws InputError when the file is missing or unreadable.
std::vector<std::byte> read_file_bytes(const std::filesystem::path& path);
std::string read_file_text(const std::filesystem::path& path);

}  // namespace mlidar::io
