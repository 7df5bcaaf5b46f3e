// Every sub-command's --help ends with real examples: each names the
// sub-command, uses only options its help lists, and parses (run where its
// inputs are missing, it fails on the input, exit 3, never on the command line).
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "apps/cli_runner.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

/// The examples' lines of a help text ("  mlidar ..." after "Examples:").
std::vector<std::string> example_lines(const std::string& help) {
  std::vector<std::string> lines;
  std::istringstream in(help.substr(help.find("Examples:") == std::string::npos ? help.size() : help.find("Examples:")));
  for (std::string line; std::getline(in, line);)
    if (line.rfind("  mlidar ", 0) == 0) lines.push_back(line.substr(2));
  return lines;
}

std::vector<std::string> option_names(const std::string& command_line) {
  std::vector<std::string> names;
  std::istringstream in(command_line);
  for (std::string token; in >> token;)
    if (token.rfind("--", 0) == 0) names.push_back(token);
  return names;
}

TEST(CliHelp, EverySubCommandEndsWithExamplesThatParse) {
  const std::vector<std::string> commands = {
      "info",           "convert",  "simulate drive", "simulate corner", "simulate detection", "calibrate planes", "calibrate refine",
      "calibrate auto", "odometry", "slam",           "bag info",        "bag export",         "perturb",          "eval traj",
      "eval calib",     "eval map", "eval detections"};
  const std::filesystem::path dir = scratch_dir();
  std::filesystem::create_directories(dir / "run");  // the folder `eval traj --plot run/...` writes into
  for (const std::string& command : commands) {
    SCOPED_TRACE(command);
    const CliResult help = run_cli(command + " --help");
    ASSERT_EQ(help.exit_code, 0) << help.output;
    const std::vector<std::string> examples = example_lines(help.output);
    ASSERT_FALSE(examples.empty()) << help.output;
    EXPECT_LE(examples.size(), 2u);
    for (const std::string& example : examples) {
      EXPECT_EQ(example.rfind("mlidar " + command + " ", 0), 0u) << example;
      for (const std::string& option : option_names(example))
        EXPECT_NE(help.output.find("  " + option + " "), std::string::npos) << option << " in: " << example;
      if (command.rfind("simulate", 0) == 0) continue;  // would simulate a whole drive: options checked above
      // In an empty folder the inputs are missing: bad input (3), not a usage error (2).
      const CliResult run = run_shell("cd " + quoted(dir.string()) + " && " + mlidar_bin() + example.substr(6));
      EXPECT_EQ(run.exit_code, 3) << example << "\n" << run.output;
    }
  }
  // Nothing was written by the examples that failed on their input.
  std::vector<std::string> left;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"run"});
}

}  // namespace
}  // namespace mlidar::test
