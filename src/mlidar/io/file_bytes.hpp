#pragma once
// Reads a whole file into memory, with errors that name the file. "-" is the
// standard input; pipes and process substitutions (/dev/fd/N) are read to
// their end, once.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace mlidar::io {

/// Throws InputError when the file is missing, a folder or unreadable.
std::vector<std::byte> read_file_bytes(const std::filesystem::path& path);
std::string read_file_text(const std::filesystem::path& path);

/// True for "-" and for paths that are no regular file (pipes, /dev/fd/N): their name tells nothing of their format.
bool is_stream_path(const std::filesystem::path& path);

}  // namespace mlidar::io
