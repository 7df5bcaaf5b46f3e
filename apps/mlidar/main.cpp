// mlidar command-line entry point: parses the command line and maps errors to
// the documented exit codes (0 ok, 1 untrusted/failed, 2 usage, 3 bad input).
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>

#include "apps/mlidar/commands.hpp"
#include "mlidar/core/error.hpp"

int main(int argc, char** argv) {
  using mlidar::ExitCode;
  CLI::App app{"mlidar: calibration, odometry, mapping and detection for robots with several LiDARs"};
  app.footer(
      "Exit codes:\n"
      "  0  ok\n"
      "  1  the job ran but failed or its result should not be trusted (no convergence, degenerate)\n"
      "  2  usage error (bad command line or configuration, output that cannot be written)\n"
      "  3  bad input data (unreadable, truncated or invalid file)");
  app.require_subcommand(1);
  app.set_version_flag("--version", "mlidar 0.1.0");
  const auto commands = mlidar::cli::register_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : static_cast<int>(ExitCode::kUsage);
  }
  try {
    for (const auto& command : commands) {
      if (command.sub->parsed()) return command.run();
    }
    return static_cast<int>(ExitCode::kUsage);
  } catch (const mlidar::InputError& e) {
    std::cerr << "mlidar: error: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kBadInput);
  } catch (const mlidar::UsageError& e) {
    std::cerr << "mlidar: usage error: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kUsage);
  } catch (const mlidar::OutputError& e) {
    std::cerr << "mlidar: cannot write output: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kUsage);
  } catch (const std::exception& e) {
    std::cerr << "mlidar: failed: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kUntrusted);
  }
}
