// mlidar fleet run: many recordings x tasks on Dask through the Python bindings (python/mlidar/fleet.py). This
// command checks its options, finds the package beside the executable (installed) or in the build tree, and
// replaces itself with `python3 -m mlidar.fleet run ...`, so signals and the exit code are the fleet's own.
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/mlidar/commands.hpp"
#include "mlidar/core/error.hpp"

namespace mlidar::cli {
namespace {

namespace fs = std::filesystem;

struct FleetOptions {
  std::string jobs;
  std::string out;
  std::string scheduler;
  int local = 0;
};

/// The folder holding the `mlidar` package: the install's (PREFIX/bin/mlidar -> PREFIX/<site-packages>) first,
/// then the build tree's.
[[maybe_unused]] std::optional<fs::path> python_package_root() {  // unused without the Python module
#ifdef MLIDAR_PYTHON_INSTALL_DIR
  if (const std::optional<fs::path> executable = this_executable()) {
    const fs::path installed = executable->parent_path().parent_path() / MLIDAR_PYTHON_INSTALL_DIR;
    if (fs::exists(installed / "mlidar" / "fleet.py")) return installed;
  }
  const fs::path built = MLIDAR_PYTHON_BUILD_DIR;
  if (fs::exists(built / "mlidar" / "fleet.py")) return built;
#endif
  return std::nullopt;
}

int run_fleet(const FleetOptions& options) {
#ifndef MLIDAR_PYTHON_EXECUTABLE
  (void)options;
  std::cerr << "mlidar fleet: this mlidar was built without the Python module (it needs Debian's pybind11-dev and "
               "python3-dev at build time; -DMLIDAR_WITH_PYTHON=ON)\n";
  return static_cast<int>(ExitCode::kUsage);
#else
  const std::optional<fs::path> package = python_package_root();
  if (!package) {
    std::cerr << "mlidar fleet: the Python package mlidar is neither installed beside this executable nor in its build "
                 "tree (build it, or `cmake --install`)\n";
    return static_cast<int>(ExitCode::kUsage);
  }
  const char* previous = std::getenv("PYTHONPATH");
  const std::string python_path = package->string() + (previous && *previous ? ":" + std::string(previous) : "");
  setenv("PYTHONPATH", python_path.c_str(), 1);
  std::vector<std::string> arguments = {MLIDAR_PYTHON_EXECUTABLE, "-m", "mlidar.fleet", "run", "--jobs", options.jobs,
                                        "--out", options.out};
  if (!options.scheduler.empty()) arguments.insert(arguments.end(), {"--scheduler", options.scheduler});
  if (options.local > 0) arguments.insert(arguments.end(), {"--local", std::to_string(options.local)});
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  // main() blocks SIGINT and SIGTERM for its signal thread; the fleet handles them itself.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);
  execv(MLIDAR_PYTHON_EXECUTABLE, argv.data());
  std::cerr << "mlidar fleet: cannot start " << MLIDAR_PYTHON_EXECUTABLE << ": " << std::strerror(errno) << '\n';
  return static_cast<int>(ExitCode::kUsage);
#endif
}

}  // namespace

Command register_fleet(CLI::App& app) {
  auto options = std::make_shared<FleetOptions>();
  CLI::App* fleet = app.add_subcommand("fleet", "Fleet runs: many recordings x tasks on a Dask cluster, one summary");
  fleet->require_subcommand(1);
  CLI::App* sub = fleet->add_subcommand(
      "run",
      "Run every job of a jobs file (calibrate-auto, slam, eval, doctor on a recording) as Dask tasks into --out: "
      "jobs/ID/ per job, fleet.json and fleet.html (verdicts; has a LiDAR moved between recordings?). Run it again "
      "to resume: complete jobs are reused. Exit 1 when a job failed or is not trusted, or a LiDAR moved");
  sub->add_option("--jobs", options->jobs, "jobs.yaml (format: docs/fleet.md)")->required()->check(CLI::ExistingFile);
  sub->add_option("--out", options->out, "Fleet folder: new, empty, or an earlier fleet run (resumed)")->required();
  auto* scheduler = sub->add_option("--scheduler", options->scheduler,
                                    "Address of a running Dask scheduler (tcp://HOST:8786); its workers must see the "
                                    "recordings and --out at the same paths");
  sub->add_option("--local", options->local, "Worker processes of a local Dask cluster (default: the cores)")
      ->check(CLI::Range(1, 1024))
      ->excludes(scheduler);
  return {fleet, [options] { return run_fleet(*options); }};
}

}  // namespace mlidar::cli
