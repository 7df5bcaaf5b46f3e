// `mlidar odometry`: multi-LiDAR scan-to-map odometry over a dataset or a folder of clouds.
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "apps/mlidar/commands.hpp"
#include "apps/mlidar/progress_bar.hpp"
#include "mlidar/pipelines/odometry_job.hpp"

namespace mlidar::cli {
namespace {

struct OdometryOptions {
  std::string dataset;
  std::string scans;
  double period = 0.1;
  std::string lidars;
  int threads = 0;
  std::string out;
};

std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream stream(text);
  for (std::string name; std::getline(stream, name, ',');)
    if (!name.empty()) names.push_back(name);
  return names;
}

int run_odometry(const OdometryOptions& options) {
  pipelines::OdometryJob job;
  job.dataset = options.dataset;
  job.scans = options.scans;
  job.period = options.period;
  job.lidars = split_names(options.lidars);
  job.threads = options.threads;
  job.out = options.out;
  const auto summary = pipelines::run_odometry_job(job, terminal_progress_bar());
  std::cout << "wrote " << options.out << ": " << summary.frames << " frames, " << summary.mean_frame_seconds * 1e3 << " ms per frame, "
            << summary.degenerate_frames << " degenerate, " << summary.lost_frames << " lost\n";
  if (summary.degenerate_frames > 0)
    std::cerr << "warning: " << summary.degenerate_frames << " frame(s) degenerate (translation weakly constrained, e.g. a corridor); see metrics.json\n";
  if (summary.lost_frames > 0) std::cerr << "warning: " << summary.lost_frames << " frame(s) could not be registered; see metrics.json\n";
  return summary.lost_frames > 0 ? 1 : 0;
}

}  // namespace

Command register_odometry(CLI::App& app) {
  auto options = std::make_shared<OdometryOptions>();
  CLI::App* sub = app.add_subcommand("odometry", "Scan-to-map odometry from all LiDARs at once (known extrinsics)");
  auto* dataset = sub->add_option("--dataset", options->dataset, "Dataset folder (dataset.yaml, times.txt, scans/)");
  auto* scans = sub->add_option("--scans", options->scans, "Folder of single-LiDAR clouds, taken in natural order");
  dataset->excludes(scans);
  sub->add_option("--period", options->period, "Seconds between clouds of --scans")->capture_default_str();
  sub->add_option("--lidars", options->lidars, "Comma-separated LiDAR names of the dataset (default: all)");
  sub->add_option("--threads", options->threads, "Worker threads (0: all cores)")->capture_default_str();
  sub->add_option("--out", options->out, "Run folder: trajectory.tum, trajectory.kitti, map.ply, metrics.json")->required();
  return {sub, [options] { return run_odometry(*options); }};
}

}  // namespace mlidar::cli
