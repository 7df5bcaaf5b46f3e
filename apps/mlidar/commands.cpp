#include "apps/mlidar/commands.hpp"

#include <sstream>
#include <thread>

namespace mlidar::cli {

std::optional<std::filesystem::path> this_executable() {
  std::error_code ec;
  std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return std::nullopt;
  return executable;
}

CLI::Validator thread_count() {
  const int cores = static_cast<int>(std::max(1U, std::thread::hardware_concurrency()));
  return CLI::Range(0, 4 * cores).description("0 (all cores) to " + std::to_string(4 * cores) + " (4 x the cores)");
}

CLI::Validator share() { return CLI::Range(0.0, 1.0).description("a share in [0, 1]"); }

CLI::Option* add_overwrite_flag(CLI::App& sub, bool& overwrite) {
  return sub.add_flag("--overwrite", overwrite,
                      "Replace --out even when it is not an earlier mlidar run folder (a folder holding other files)");
}

CLI::Option* add_max_base_gaps_option(CLI::App& sub, double& max_base_gaps) {
  return sub
      .add_option("--max-base-gaps", max_base_gaps,
                  "Largest share of frames the base LiDAR may lack a usable scan in (missing, empty, all NaN) before the job "
                  "fails with exit 1")
      ->check(share())
      ->capture_default_str();
}

std::string suspect_frames_warning(const std::vector<std::size_t>& frames) {
  if (frames.empty()) return {};
  std::ostringstream text;
  text << "warning: " << frames.size() << (frames.size() == 1 ? " frame suspect (frame " : " frames suspect (frames ");
  for (std::size_t i = 0; i < frames.size() && i < 10; ++i) text << (i > 0 ? ", " : "") << frames[i];
  if (frames.size() > 10) text << " and " << frames.size() - 10 << " more";
  text << ", from 0): the best registration fits clearly worse than the frames before, another alignment fits as well, or "
          "it is degenerate and moved far from the motion prior; the pose may be wrong and the frame was kept out of the map (metrics.json "
          "per_frame trust)\n";
  return text.str();
}

}  // namespace mlidar::cli
