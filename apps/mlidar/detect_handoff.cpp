// mlidar's `detect train|run` (detect_command.hpp): the command line, already checked here, run again as
// mlidar-detect in this process (exec), so that LibTorch is loaded only by the commands that use it.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "apps/mlidar/detect_command.hpp"
#include "mlidar/core/error.hpp"

namespace mlidar::cli {
namespace {

namespace fs = std::filesystem;

#if MLIDAR_WITH_DETECT

constexpr const char* kDetectExecutable = "mlidar-detect";

/// The executables mlidar-detect may be: beside this one (the build tree), or in libexec/mlidar of its prefix.
std::vector<fs::path> detect_executable_candidates() {
  const std::optional<fs::path> self = this_executable();
  if (!self) return {};
  return {self->parent_path() / kDetectExecutable, self->parent_path().parent_path() / MLIDAR_LIBEXEC_DIR / kDetectExecutable};
}

[[noreturn]] void hand_over(const CliContext& context) {
  const std::vector<fs::path> candidates = detect_executable_candidates();
  std::string looked;
  for (const fs::path& candidate : candidates) {
    looked += (looked.empty() ? "" : ", ") + candidate.string();
    if (access(candidate.c_str(), X_OK) != 0) continue;
    std::vector<std::string> arguments = context.arguments;  // argv[0] kept: messages and run.json name mlidar
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    argv.push_back(nullptr);
    std::cout.flush();
    execv(candidate.c_str(), argv.data());
    throw UsageError("cannot start " + candidate.string() + ": " + std::strerror(errno));
  }
  throw UsageError(std::string("mlidar-detect, which runs `detect train|run` on LibTorch, is not where this mlidar looks for it (") +
                   (looked.empty() ? "/proc/self/exe unreadable" : looked) +
                   "): build the target mlidar-detect beside mlidar, or install both with `cmake --install`");
}

#else

[[noreturn]] void hand_over(const CliContext&) {
  throw UsageError("this mlidar was built without LibTorch (MLIDAR_WITH_DETECT=OFF): install libtorch-dev "
                   "(scripts/install_deps.sh does) and build again to train and run detectors");
}

#endif

}  // namespace

DetectJobs detect_handoff(const CliContext& context) {
  return {[&context](const DetectTrainOptions&) -> int { hand_over(context); },
          [&context](const DetectRunOptions&) -> int { hand_over(context); }};
}

}  // namespace mlidar::cli
