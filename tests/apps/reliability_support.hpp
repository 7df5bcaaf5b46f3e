#pragma once
// Shared by the reliability tests (issue 15): a small simulated dataset,
// checksums of whole folders (to prove nothing the user had changed), and a
// child mlidar process that can be signalled at its write step.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "apps/cli_runner.hpp"
#include "test_support.hpp"

namespace mlidar::test {

namespace fs = std::filesystem;

/// Relative path -> content hash of every file and folder under `root` (links not followed).
inline std::map<std::string, std::size_t> folder_checksums(const fs::path& root) {
  std::map<std::string, std::size_t> sums;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const std::string name = fs::relative(entry.path(), root).string();
    if (entry.is_regular_file()) {
      std::ifstream in(entry.path(), std::ios::binary);
      sums[name] = std::hash<std::string>{}(std::string(std::istreambuf_iterator<char>(in), {}));
    } else {
      sums[name] = 0;
    }
  }
  return sums;
}

/// Entries of `folder` whose names hold `part` (staging folders, temporary files).
inline std::vector<std::string> entries_containing(const fs::path& folder, const std::string& part) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.path().filename().string().find(part) != std::string::npos) found.push_back(entry.path().filename().string());
  return found;
}

/// The rhd rig (left base, right) in the room, 12 frames: simulated once per build of mlidar (under a lock, as the
/// tests run in parallel processes) and only read afterwards.
inline const fs::path& small_dataset() {
  static const fs::path dataset = [] {
    const auto built = fs::last_write_time(mlidar_bin()).time_since_epoch().count();
    const std::size_t tree = std::hash<std::string>{}(mlidar_bin() + std::to_string(built));
    const fs::path dir = fs::temp_directory_path() / "mlidar_tests" / std::to_string(tree % 1000000007u) / "reliability_dataset";
    fs::create_directories(dir);
    const int lock = ::open((dir / "lock").c_str(), O_CREAT | O_RDWR, 0644);
    ::flock(lock, LOCK_EX);
    if (!fs::exists(dir / "sim" / "dataset.yaml")) {
      const CliResult r = run_cli("simulate drive --rig rhd --scene room --trajectory handheld --frames 12 --seed 2 --out " +
                                  quoted((dir / "sim").string()));
      EXPECT_EQ(r.exit_code, 0) << r.output;
    }
    ::flock(lock, LOCK_UN);
    ::close(lock);
    return dir / "sim";
  }();
  return dataset;
}

/// A full copy of the small dataset at `to` (tests may break its files).
inline fs::path copy_of_small_dataset(const fs::path& to) {
  fs::copy(small_dataset(), to, fs::copy_options::recursive);
  return to;
}

/// An mlidar child whose stderr is read until a line holding `marker`, then signalled.
struct Interrupted {
  int exit_code = -1;
  bool saw_marker = false;
  std::string output;
};

/// Runs mlidar `arguments` (a vector, no shell) with MLIDAR_TEST_PAUSE=`pause`, waits for its pause
/// announcement, sends `signal`, and returns its exit code.
inline Interrupted interrupt_at_pause(const std::vector<std::string>& arguments, const char* pause, int signal) {
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(pipe_fds[1], STDERR_FILENO);
    ::dup2(pipe_fds[1], STDOUT_FILENO);
    ::close(pipe_fds[0]);
    ::setenv("MLIDAR_TEST_PAUSE", pause, 1);
    const std::string bin = mlidar_bin();
    std::vector<char*> argv{const_cast<char*>(bin.c_str())};
    for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(bin.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(pipe_fds[1]);
  Interrupted result;
  char buffer[512];
  for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;) {
    result.output.append(buffer, static_cast<std::size_t>(n));
    if (!result.saw_marker && result.output.find("test pause before rename") != std::string::npos) {
      result.saw_marker = true;
      ::kill(pid, signal);
    }
  }
  ::close(pipe_fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace mlidar::test
