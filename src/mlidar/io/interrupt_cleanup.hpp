#pragma once
// What an interrupted run leaves behind is removed: the temporary files and
// staging folders of unfinished outputs are registered here while they exist,
// and io::remove_unfinished_outputs() (called by the CLI's SIGINT/SIGTERM
// handler thread) deletes them. This is process-wide state on purpose:
// signals are process-wide. The registry's lock is held while a registered
// path is created or renamed, so the handler never races a rename.
#include <filesystem>
#include <mutex>

namespace mlidar::io {

/// A registered path: removed by remove_unfinished_outputs() until released (or destroyed, which only unregisters).
class UnfinishedOutput {
 public:
  explicit UnfinishedOutput(std::filesystem::path path);
  ~UnfinishedOutput();
  UnfinishedOutput(const UnfinishedOutput&) = delete;
  UnfinishedOutput& operator=(const UnfinishedOutput&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// True when `path` lies inside a registered folder (a run folder's staging folder): written there, a file needs
/// no temporary name or flush of its own, as the folder appears whole or not at all.
bool inside_unfinished_folder(const std::filesystem::path& path);

/// Held while a registered output is created, written into place or renamed.
std::unique_lock<std::mutex> lock_unfinished_outputs();

/// Removes every registered path (files and folders, recursively) and keeps the lock, so no output is
/// renamed into place afterwards: the caller exits next. Returns how many paths were removed.
std::size_t remove_unfinished_outputs();

}  // namespace mlidar::io
