// mlidar-detect: `detect train|run` on LibTorch, started by `mlidar detect train|run` with its own command line
// (detect_command.hpp). Kept apart so that every other command of mlidar starts without loading LibTorch.
#include "apps/mlidar/cli_main.hpp"
#include "apps/mlidar/detect_command.hpp"

int main(int argc, char** argv) {
  return mlidar::cli::run_command_line(argc, argv, [](CLI::App& app, const mlidar::cli::CliContext& context) {
    return std::vector<mlidar::cli::Command>{mlidar::cli::register_detect(app, mlidar::cli::detect_network_jobs(context))};
  });
}
