#pragma once
// Sub-commands of the mlidar CLI. Each command file registers its options on
// the app and returns its run function; main dispatches to the parsed one.
#include <functional>
#include <vector>

#include <CLI/CLI.hpp>

namespace mlidar::cli {

struct Command {
  CLI::App* sub = nullptr;          ///< owned by the parent CLI::App
  std::function<int()> run;         ///< returns the process exit code
};

Command register_info(CLI::App& app);
Command register_convert(CLI::App& app);
Command register_simulate(CLI::App& app);
Command register_eval(CLI::App& app);
Command register_calibrate(CLI::App& app);
/// `calibrate refine` under the `calibrate` parent (command_calibrate_refine.cpp).
Command add_calibrate_refine(CLI::App& calibrate);
Command register_odometry(CLI::App& app);
Command register_slam(CLI::App& app);

/// All sub-commands, in the order `mlidar --help` lists them.
std::vector<Command> register_commands(CLI::App& app);

}  // namespace mlidar::cli
