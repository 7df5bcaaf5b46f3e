#pragma once
// Runs the built mlidar executable (MLIDAR_BIN, set by CMake) in a shell and
// captures its exit code and combined output.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/wait.h>

namespace mlidar::test {

struct CliResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

inline CliResult run_cli(const std::string& arguments) {
  const char* bin = std::getenv("MLIDAR_BIN");
  const std::string command = std::string(bin != nullptr ? bin : "mlidar") + " " + arguments + " 2>&1";
  CliResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

/// Quotes a path for the shell.
inline std::string quoted(const std::string& text) { return "'" + text + "'"; }

}  // namespace mlidar::test
