#include "apps/mlidar/commands.hpp"

namespace mlidar::cli {

std::vector<Command> register_commands(CLI::App& app) {
  return {register_info(app),      register_convert(app),  register_simulate(app),
          register_calibrate(app), register_odometry(app), register_slam(app),
          register_eval(app)};
}

}  // namespace mlidar::cli
