#pragma once
// Outputs are written to a temporary file in the destination folder, flushed
// to disk (fsync) and renamed over the target only when complete, then the
// folder is synced, so an interrupted or failed write (a crash, a signal, a
// full disk, a power cut) never leaves a half file, or an empty one renamed
// into place. The temporary file is named PATH.tmp-PID-N; one left by a process
// that no longer runs (killed) is removed by the next write of PATH. Inside a
// run folder's staging folder (io/run_folder.hpp) a file is written straight
// to its name: the folder is flushed and published whole at its commit.
//
// Test hook: with MLIDAR_TEST_PAUSE=file in the environment, the writer prints
// "mlidar: test pause before rename" on stderr and sleeps 30 s before the
// rename (tests interrupt a run there).
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace mlidar::io {

/// Calls write(stream) on a temporary file next to `path`, then renames it
/// to `path`. On any failure the temporary file is removed and OutputError
/// (or the writer's exception) propagates.
void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

/// fsync of a file or folder; OutputError naming it when that fails.
void sync_path(const std::filesystem::path& path);

/// True when MLIDAR_TEST_PAUSE names `point` ("file" or "commit"): then it has announced the pause and slept.
bool test_pause(const char* point);

/// UsageError unless `path` can be created as an output file: its folder exists and is writable, and `path` is
/// not a folder. Checked before a job runs, so a long job does not fail at its end.
void check_output_file(const std::filesystem::path& path, const std::string& option);

}  // namespace mlidar::io
