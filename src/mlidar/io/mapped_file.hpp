#pragma once
// A file mapped read-only into memory, for the bag readers: records and
// uncompressed chunks are read in place, without a copy.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace mlidar::io {

class MappedFile {
 public:
  /// InputError naming the file when it cannot be opened or mapped.
  explicit MappedFile(const std::filesystem::path& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::span<const std::byte> bytes() const { return {data_, size_}; }
  std::size_t size() const { return size_; }

 private:
  const std::byte* data_ = nullptr;
  std::size_t size_ = 0;
};

/// A block of records: a view of the mapped file (stored uncompressed) or of the bytes it was decompressed into.
struct ChunkData {
  std::vector<std::byte> owned;
  std::span<const std::byte> view;
};

}  // namespace mlidar::io
