#pragma once
// Sub-commands of the mlidar CLI. Each command file registers its options on
// the app and returns its run function; main dispatches to the parsed one.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "mlidar/io/run_folder.hpp"

namespace mlidar::cli {

struct Command {
  CLI::App* sub = nullptr;   ///< owned by the parent CLI::App
  std::function<int()> run;  ///< returns the process exit code
};

/// What every command may need from the process: the command line, as run.json records it.
struct CliContext {
  std::vector<std::string> arguments;

  /// The run folder options of a command that writes --out (io/run_folder.hpp).
  io::RunFolderOptions run_folder(bool overwrite, std::vector<std::filesystem::path> inputs) const {
    return {overwrite, std::move(inputs), arguments};
  }
};

Command register_info(CLI::App& app);
Command register_convert(CLI::App& app);
Command register_simulate(CLI::App& app, const CliContext& context);
Command register_eval(CLI::App& app, const CliContext& context);
Command register_calibrate(CLI::App& app, const CliContext& context);
/// `calibrate refine` under the `calibrate` parent (command_calibrate_refine.cpp).
Command add_calibrate_refine(CLI::App& calibrate);
/// `eval detections` under the `eval` parent (command_eval_detections.cpp).
Command add_eval_detections(CLI::App& eval);
Command register_odometry(CLI::App& app, const CliContext& context);
Command register_slam(CLI::App& app, const CliContext& context);
Command register_bag(CLI::App& app, const CliContext& context);
Command register_report(CLI::App& app);
Command register_doctor(CLI::App& app);
Command register_perturb(CLI::App& app, const CliContext& context);
/// `fleet run`: the Python package's Dask fleet (command_fleet.cpp).
Command register_fleet(CLI::App& app);

/// Ends each sub-command's --help with one or two real examples (command_examples.cpp); after the commands are added.
void add_examples(CLI::App& app);

/// This process's executable (/proc/self/exe), to find what is installed beside it; nullopt when unreadable.
std::optional<std::filesystem::path> this_executable();

/// Worker threads a command accepts: 0 (all cores) to 4 x the cores.
CLI::Validator thread_count();
/// A share in [0, 1] (--max-base-gaps).
CLI::Validator share();

/// The warning for frames the odometry flagged suspect (0-based indices, as
/// metrics.json per_frame); empty when there are none.
std::string suspect_frames_warning(const std::vector<std::size_t>& frames);

/// The shared --overwrite flag of commands that write a run folder.
CLI::Option* add_overwrite_flag(CLI::App& sub, bool& overwrite);
/// The shared --max-base-gaps option of the jobs that read frames.
CLI::Option* add_max_base_gaps_option(CLI::App& sub, double& max_base_gaps);

}  // namespace mlidar::cli
