#pragma once
// A job's run folder (--out), staged and swapped: the job writes into a
// staging folder beside --out (.NAME.mlidar-stage-PID), and commit() writes
// run.json, flushes every file and folder to disk and only then puts the
// staging folder in place of --out (an atomic exchange where the file system
// has one), removing the previous run folder last. A crash, a signal, a full
// disk or an exception before that leaves --out exactly as it was; an
// uncommitted staging folder is removed (by the destructor, by the CLI's
// signal handler, or, after a kill -9, by the next run into the same --out).
//
// What --out may be (checked when the RunFolder is made, before the job runs):
//   - a new folder (its parent is created), or an empty folder;
//   - an earlier mlidar run folder (it holds run.json with "tool": "mlidar").
//     A dataset written by `mlidar simulate`, `bag export` or `perturb` is replaced only
//     by one of those: it is other commands' input;
//   - anything else (a folder holding other files, a dataset, a file) only
//     with --overwrite (RunFolderOptions::overwrite), never a file;
//   - never an input folder, a folder holding one, or anything inside an
//     input's groundtruth/ (not even with --overwrite).
// run.json: {tool, version, command, arguments, started_utc, finished_utc}.
//
// Test hook: MLIDAR_TEST_PAUSE=commit pauses commit() before the swap
// (io/atomic_file.hpp: test_pause).
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/io/interrupt_cleanup.hpp"

namespace mlidar::io {

struct RunFolderOptions {
  bool overwrite = false;                     ///< --overwrite: replace a folder that is not an mlidar run
  std::vector<std::filesystem::path> inputs;  ///< folders the job reads, never replaced
  std::vector<std::string> arguments;         ///< the command line, for run.json
};

class RunFolder {
 public:
  /// `command`: "odometry", "slam", "calibrate auto", "simulate drive", ... UsageError (exit 2) naming --out
  /// and why when it may not be used, or cannot be created or written.
  RunFolder(const std::filesystem::path& out, std::string command, RunFolderOptions options);
  ~RunFolder();
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  /// The staging folder: write the run's files here.
  const std::filesystem::path& path() const { return staging_->path(); }
  std::filesystem::path operator/(const std::string& name) const { return path() / name; }
  /// The folder the run ends up in.
  const std::filesystem::path& out() const { return out_; }

  /// Writes run.json, syncs, and swaps the staging folder into place. OutputError when it cannot.
  void commit();

 private:
  std::filesystem::path out_;
  std::string command_;
  RunFolderOptions options_;
  std::chrono::system_clock::time_point started_;
  std::optional<UnfinishedOutput> staging_;
  bool committed_ = false;
};

/// The command that wrote run folder `folder` (its run.json), or nullopt when it is not an mlidar run folder.
std::optional<std::string> run_folder_command(const std::filesystem::path& folder);

}  // namespace mlidar::io
