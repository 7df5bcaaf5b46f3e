// mlidar command-line entry point: every sub-command, run by cli_main.hpp (exit codes 0 ok, 1 untrusted/failed,
// 2 usage, 3 bad input, 130/143 interrupted by SIGINT/SIGTERM). `detect train|run` are parsed here and run by
// mlidar-detect, on LibTorch (detect_command.hpp).
#include "apps/mlidar/cli_main.hpp"
#include "apps/mlidar/commands.hpp"
#include "apps/mlidar/detect_command.hpp"

namespace mlidar::cli {
namespace {

/// All sub-commands, in the order `mlidar --help` lists them.
std::vector<Command> all_commands(CLI::App& app, const CliContext& context) {
  return {register_info(app),
          register_convert(app),
          register_simulate(app, context),
          register_calibrate(app, context),
          register_odometry(app, context),
          register_slam(app, context),
          register_bag(app, context),
          register_perturb(app, context),
          register_detect(app, detect_handoff(context)),
          register_eval(app, context),
          register_report(app),
          register_doctor(app),
          register_fleet(app)};
}

}  // namespace
}  // namespace mlidar::cli

int main(int argc, char** argv) {
  return mlidar::cli::run_command_line(argc, argv, mlidar::cli::all_commands, mlidar::cli::add_examples);
}
