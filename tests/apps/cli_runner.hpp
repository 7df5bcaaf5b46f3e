#pragma once
// Runs the built mlidar executable (MLIDAR_BIN overrides the path CMake compiled in) in a shell and
// captures its exit code and combined output.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace mlidar::test {

struct CliResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// The mlidar executable under test.
inline std::string mlidar_bin() {
  const char* bin = std::getenv("MLIDAR_BIN");
  return bin != nullptr ? bin : MLIDAR_TEST_BIN;
}

/// Runs `command` in /bin/sh, stderr into stdout.
inline CliResult run_shell(const std::string& command) {
  CliResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

inline CliResult run_cli(const std::string& arguments) { return run_shell(mlidar_bin() + " " + arguments); }

/// Quotes a path for the shell.
inline std::string quoted(const std::string& text) { return "'" + text + "'"; }

}  // namespace mlidar::test
