#pragma once
// The process around a command line, shared by `mlidar` and `mlidar-detect` (the LibTorch half that `mlidar detect
// train|run` hands its command line to): interrupts, parsing, and the documented exit codes.
#include <functional>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/mlidar/commands.hpp"

namespace mlidar::cli {

/// Adds a program's sub-commands to the app; `context` outlives the returned commands.
using CommandRegistry = std::function<std::vector<Command>(CLI::App& app, const CliContext& context)>;

/// Parses argv against the commands `register_all` adds (then `decorate` runs on the app, e.g. the examples) and runs
/// the parsed one. Exit codes: 0 ok, 1 the job failed or should not be trusted, 2 usage, 3 bad input; SIGINT and
/// SIGTERM remove the unfinished outputs and exit 130 and 143.
int run_command_line(int argc, char** argv, const CommandRegistry& register_all,
                     const std::function<void(CLI::App&)>& decorate = {});

}  // namespace mlidar::cli
