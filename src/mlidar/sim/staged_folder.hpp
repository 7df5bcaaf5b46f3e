#pragma once
// An output folder built under a temporary name next to its destination and
// renamed into place only when complete: a failed run leaves nothing behind.
#include <filesystem>

namespace mlidar::sim {

class StagedFolder {
 public:
  /// Refuses (UsageError) when `destination` exists and is not an empty
  /// folder, or when its parent folder cannot be created or written.
  explicit StagedFolder(std::filesystem::path destination);
  /// Removes the temporary folder unless commit() succeeded.
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  /// Where to write while the folder is being built.
  const std::filesystem::path& path() const { return staging_; }
  /// Renames the finished folder to its destination (OutputError on failure).
  void commit();

 private:
  std::filesystem::path destination_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

}  // namespace mlidar::sim
