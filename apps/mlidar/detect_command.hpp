#pragma once
// `mlidar detect train|run` (MLOD, src/mlidar/detect/net/detector.hpp). The command line is parsed twice: by mlidar,
// which checks it, answers --help and then hands it over unchanged (exec, same process) to mlidar-detect, the
// executable on LibTorch that parses it again and runs the job. mlidar itself does not load LibTorch: loading it took
// a second of every command's start (0.7 s of CPU in the dynamic loader and LibTorch's start-up).
#include <cstdint>
#include <functional>
#include <string>

#include "apps/mlidar/commands.hpp"

namespace mlidar::cli {

struct DetectTrainOptions {
  std::string data, config, fusion = "input", lidar, out;
  int stage = 0;
  bool resume = false;
  long max_steps = 0;
  int threads = 0;
};

struct DetectRunOptions {
  std::string model, dataset, out;
  double alpha = 0.0;
  std::uint64_t seed = 1;
  int stage = 0;
  int threads = 0;
  bool overwrite = false;
  bool refine_extrinsics = false;
};

/// What the parsed `detect train` and `detect run` do; each returns the exit code.
struct DetectJobs {
  std::function<int(const DetectTrainOptions&)> train;
  std::function<int(const DetectRunOptions&)> run;
};

/// `detect` with its two sub-commands and their options (command_detect.cpp).
Command register_detect(CLI::App& app, DetectJobs jobs);

/// mlidar's jobs (detect_handoff.cpp): this process's command line run again as mlidar-detect, found beside the
/// executable (the build tree) or in libexec/mlidar of its prefix (installed). Built without LibTorch, or without
/// mlidar-detect to be found, a usage error (exit 2) that says how to get it.
DetectJobs detect_handoff(const CliContext& context);

/// mlidar-detect's jobs (detect_jobs.cpp, on LibTorch): training and detection.
DetectJobs detect_network_jobs(const CliContext& context);

}  // namespace mlidar::cli
