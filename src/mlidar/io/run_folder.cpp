#include "mlidar/io/run_folder.hpp"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/core/version.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"

namespace mlidar::io {
namespace {

namespace fs = std::filesystem;

constexpr const char* kStageTag = ".mlidar-stage-";

fs::path normalized(const fs::path& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  return p;
}

/// `inner` is `outer` or lies inside it (lexically, after normalization and following links that exist).
bool is_within(const fs::path& inner, const fs::path& outer) {
  std::error_code ec;
  const fs::path a = fs::weakly_canonical(inner, ec);
  const fs::path b = fs::weakly_canonical(outer, ec);
  auto ai = a.begin();
  for (auto bi = b.begin(); bi != b.end(); ++bi, ++ai) {
    if (bi->empty()) continue;  // a trailing separator
    if (ai == a.end() || *ai != *bi) return false;
  }
  return true;
}

/// ".NAME.mlidar-stage-": the start of `out`'s staging folders' names (PID follows).
std::string staging_prefix(const fs::path& out) {
  std::string prefix = ".";
  prefix += out.filename().string();
  prefix += kStageTag;
  return prefix;
}

/// Commands whose output is a dataset: other commands' input, replaced only by a command that writes datasets.
bool writes_dataset(const std::string& command) {
  return command.rfind("simulate", 0) == 0 || command == "bag export" || command == "perturb";
}

std::string utc_text(std::chrono::system_clock::time_point time) {
  const std::time_t t = std::chrono::system_clock::to_time_t(time);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

[[noreturn]] void refuse(const fs::path& out, const std::string& why) { throw UsageError("--out " + out.string() + ": " + why); }

/// Why `out` may not receive a run of `command`, or empty.
void check_destination(const fs::path& out, const std::string& command, const RunFolderOptions& options) {
  for (const fs::path& input : options.inputs) {
    if (is_within(input, out)) refuse(out, "would replace the input " + input.string() + " (choose a folder outside it)");
    if (is_within(out, input / "groundtruth")) refuse(out, "lies inside the input's groundtruth/ (choose a folder outside it)");
  }
  std::error_code ec;
  const fs::file_status status = fs::status(out, ec);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) refuse(out, "is a file, not a folder (give a folder for the run)");
  if (fs::is_empty(out, ec)) return;
  const std::optional<std::string> previous = run_folder_command(out);
  if (options.overwrite) return;
  if (!previous)
    refuse(out,
           "holds files and is not an mlidar run folder (it has no run.json); give a new or empty folder, or add "
           "--overwrite to replace it and everything in it");
  if (writes_dataset(*previous) && !writes_dataset(command))
    refuse(out, "is a dataset written by `mlidar " + *previous + "` (input for other commands); give another folder, or add --overwrite");
}

/// Removes staging folders of `out` left by processes that no longer run (kill -9, power cut).
void remove_stale_stages(const fs::path& out) {
  const std::string prefix = staging_prefix(out);
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(out.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + prefix.size(), nullptr, 10);
    if (pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) fs::remove_all(entry.path(), ec);
  }
}

fs::path make_staging(const fs::path& out) {
  std::error_code ec;
  fs::create_directories(out.parent_path(), ec);
  if (!fs::is_directory(out.parent_path()))
    refuse(out, "cannot create its parent folder" + (ec ? " (" + ec.message() + ")" : std::string()));
  remove_stale_stages(out);
  const fs::path staging = out.parent_path() / (staging_prefix(out) + std::to_string(::getpid()));
  fs::remove_all(staging, ec);
  if (!fs::create_directory(staging, ec) || ::access(staging.c_str(), W_OK) != 0)
    refuse(out, "cannot create a folder beside it (" + (ec ? ec.message() : std::string(std::strerror(errno))) + "; check that " +
                    out.parent_path().string() + " is writable)");
  return staging;
}

/// Flushes every file and folder under `root` to disk: one syncfs of its file system (a fsync per file cost
/// 2 of 5.6 s exporting 1600 scans).
void sync_tree(const fs::path& root) {
  const int fd = ::open(root.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw OutputError(root.string() + ": cannot open to flush it to disk: " + std::strerror(errno));
  const int result = ::syncfs(fd);
  const int error = errno;
  ::close(fd);
  if (result != 0) throw OutputError(root.string() + ": cannot flush to disk: " + std::strerror(error));
}

/// Puts `staging` at `out`; when `out` exists, the two are exchanged atomically where the file system can (then
/// `staging` holds the previous run), else the previous one is moved aside first.
void swap_into_place(const fs::path& staging, const fs::path& out) {
  std::error_code ec;
  if (!fs::exists(out, ec)) {
    fs::rename(staging, out, ec);
    if (ec) throw OutputError(out.string() + ": cannot move the finished run into place: " + ec.message());
    return;
  }
  if (::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, out.c_str(), RENAME_EXCHANGE) == 0) return;
  const fs::path aside = staging.string() + "-previous";
  fs::rename(out, aside, ec);
  if (ec) throw OutputError(out.string() + ": cannot move the previous run aside: " + ec.message());
  fs::rename(staging, out, ec);
  if (ec) {
    fs::rename(aside, out);
    throw OutputError(out.string() + ": cannot move the finished run into place: " + ec.message());
  }
  fs::rename(aside, staging, ec);
}

}  // namespace

std::optional<std::string> run_folder_command(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_regular_file(folder / "run.json", ec)) return std::nullopt;
  try {
    const nlohmann::json run = nlohmann::json::parse(read_file_text(folder / "run.json"));
    if (run.value("tool", "") != "mlidar" || !run.contains("command") || !run["command"].is_string()) return std::nullopt;
    return run["command"].get<std::string>();
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

RunFolder::RunFolder(const fs::path& out, std::string command, RunFolderOptions options)
    : out_(normalized(out)), command_(std::move(command)), options_(std::move(options)), started_(std::chrono::system_clock::now()) {
  if (out.empty()) throw UsageError("--out: give a folder for the run");
  check_destination(out_, command_, options_);
  staging_.emplace(make_staging(out_));
}

RunFolder::~RunFolder() {
  if (committed_ || !staging_) return;
  std::error_code ignored;
  fs::remove_all(staging_->path(), ignored);
}

void RunFolder::commit() {
  const nlohmann::json run = {{"tool", "mlidar"},
                              {"version", kVersion},
                              {"command", command_},
                              {"arguments", options_.arguments},
                              {"started_utc", utc_text(started_)},
                              {"finished_utc", utc_text(std::chrono::system_clock::now())}};
  const std::string text = run.dump(2);
  write_atomically(path() / "run.json", [&](std::ostream& stream) { stream << text << '\n'; });
  sync_tree(path());
  test_pause("commit");
  {
    const auto lock = lock_unfinished_outputs();
    swap_into_place(path(), out_);
  }
  sync_path(out_.parent_path());
  committed_ = true;
  std::error_code ignored;
  fs::remove_all(path(), ignored);  // the previous run, when there was one
}

}  // namespace mlidar::io
