// The process around a command line (cli_main.hpp): interrupts, parsing, exit codes.
#include "apps/mlidar/cli_main.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <iostream>
#include <thread>

#include "mlidar/core/error.hpp"
#include "mlidar/core/heap_settings.hpp"
#include "mlidar/core/version.hpp"
#include "mlidar/io/interrupt_cleanup.hpp"

namespace mlidar::cli {
namespace {

/// SIGINT and SIGTERM go to one thread (blocked everywhere else, before any worker thread starts): it removes the
/// unfinished outputs (temporary files, staging folders) and exits 128 + the signal (130, 143).
void handle_interrupts() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread([signals] {
    int signal = 0;
    if (sigwait(&signals, &signal) != 0) return;
    const std::size_t removed = io::remove_unfinished_outputs();
    std::fprintf(stderr, "mlidar: interrupted (%s); removed %zu unfinished output(s), earlier outputs are unchanged\n",
                 signal == SIGINT ? "SIGINT" : "SIGTERM", removed);
    _exit(128 + signal);
  }).detach();
}

}  // namespace

int run_command_line(int argc, char** argv, const CommandRegistry& register_all, const std::function<void(CLI::App&)>& decorate) {
  keep_large_buffers_in_the_heap();  // core/heap_settings.hpp
  handle_interrupts();
  CLI::App app{"mlidar: calibration, odometry, mapping and detection for robots with several LiDARs"};
  app.footer(
      "Exit codes:\n"
      "  0    ok\n"
      "  1    the job ran but failed or its result should not be trusted (no convergence, degenerate)\n"
      "  2    usage error (bad command line, an output that cannot be written or may not be replaced)\n"
      "  3    bad input data or configuration file (the message names the file and field)\n"
      "  130  interrupted (SIGINT), 143 terminated (SIGTERM): unfinished outputs removed, earlier ones unchanged");
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("mlidar ") + kVersion);
  const CliContext context{std::vector<std::string>(argv, argv + argc)};
  const std::vector<Command> commands = register_all(app, context);
  if (decorate) decorate(app);
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
  } catch (const InputError& e) {
    std::cerr << "mlidar: error: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kBadInput);
  } catch (const UsageError& e) {
    std::cerr << "mlidar: usage error: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kUsage);
  } catch (const OutputError& e) {
    std::cerr << "mlidar: cannot write output: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kUsage);
  } catch (const std::bad_alloc&) {
    std::cerr << "mlidar: failed: out of memory\n";
    return static_cast<int>(ExitCode::kUntrusted);
  } catch (const std::exception& e) {
    std::cerr << "mlidar: failed: " << e.what() << '\n';
    return static_cast<int>(ExitCode::kUntrusted);
  }
}

}  // namespace mlidar::cli
