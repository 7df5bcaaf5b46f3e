#include "apps/mlidar/commands.hpp"

namespace mlidar::cli {

std::vector<Command> register_commands(CLI::App& /*app*/) { return {}; }

}  // namespace mlidar::cli
