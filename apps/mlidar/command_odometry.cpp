// `mlidar odometry`: multi-LiDAR scan-to-map odometry over a dataset or a folder of clouds.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include "apps/mlidar/bag_options.hpp"
#include "apps/mlidar/commands.hpp"
#include "apps/mlidar/progress_bar.hpp"
#include "mlidar/calib/extrinsic_check.hpp"
#include "mlidar/pipelines/odometry_job.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"
#include "mlidar/report/run_report.hpp"
#include "mlidar/sim/lidar_models.hpp"

namespace mlidar::cli {
namespace {

struct OdometryOptions {
  std::string dataset;
  std::string scans;
  BagCliOptions bag;
  double period = 0.1;
  std::string times;
  std::string model;
  std::string lidars;
  int threads = 0;
  double max_base_gaps = pipelines::kDefaultMaxBaseGaps;
  bool overwrite = false;
  std::string config;
  std::string out;
};

std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream stream(text);
  for (std::string name; std::getline(stream, name, ',');)
    if (!name.empty()) names.push_back(name);
  return names;
}

int run_odometry(const OdometryOptions& options, const CliContext& context) {
  const std::string input = !options.dataset.empty() ? options.dataset : !options.scans.empty() ? options.scans : options.bag.bag;
  io::RunFolder run(options.out, "odometry", context.run_folder(options.overwrite, {input}));
  pipelines::OdometryJob job;
  job.dataset = options.dataset;
  job.scans = options.scans;
  job.bag = options.bag.bag;
  job.bag_options = bag_source_options(options.bag);
  job.period = options.period;
  if (!options.times.empty()) job.times = options.times;
  if (!options.model.empty()) job.scan_model = sim::lidar_model(options.model);
  job.lidars = split_names(options.lidars);
  job.threads = options.threads;
  job.max_base_gaps = options.max_base_gaps;
  job.config = options.config;
  if (job.bag.empty()) job.extrinsics = options.bag.extrinsics;  // a dataset's or clouds' extrinsics replaced (a bag's: bag_options)
  job.out = run.path();
  const auto summary = pipelines::run_odometry_job(job, terminal_progress_bar());
  report::write_run_report(run.path(), {"odometry", options.dataset, options.out});
  run.commit();
  std::cout << "wrote " << options.out << ": " << summary.frames << " frames, " << summary.mean_frame_seconds * 1e3 << " ms per frame, "
            << summary.degenerate_frames << " degenerate, " << summary.lost_frames << " lost, " << summary.suspect_frames.size()
            << " suspect\n";
  for (const auto& line : summary.front_end) std::cout << "note: " << line << '\n';
  std::cout << "note: " << pipelines::last_pose_note(summary.last_pose_covariance, summary.lost_at_end) << '\n';
  if (summary.degenerate_frames > 0) {
    std::cerr << "warning: " << summary.degenerate_frames << " frame(s) degenerate (translation weakly constrained, e.g. a corridor): ";
    for (std::size_t i = 0; i < summary.degenerate_directions.size(); ++i)
      std::cerr << (i > 0 ? ", " : "") << "along the base's " << summary.degenerate_directions[i].first << " in "
                << summary.degenerate_directions[i].second;
    std::cerr << "; that translation was held at the motion prior, not measured (metrics.json per_frame weak_direction)\n";
  }
  std::cerr << suspect_frames_warning(summary.suspect_frames);
  std::cerr << summary.map_restart_warning;
  if (summary.lost_frames > 0) std::cerr << "warning: " << summary.lost_frames << " frame(s) could not be registered; see metrics.json\n";
  for (const auto& line : summary.gaps) std::cerr << "warning: " << line << "; see metrics.json skipped_scans\n";
  if (summary.base_failure) std::cerr << "error: " << *summary.base_failure << '\n';
  for (const pipelines::GivenExtrinsicDisagreement& d : summary.disagreements)
    std::cerr << "warning: " << d.lidar << ": the given extrinsic disagrees with the map ("
              << calib::describe(
                     {.frame = d.frame, .residual_ratio = d.residual_ratio, .map_ratio = d.map_ratio, .reference = d.compared_with})
              << "): the trajectory and map may be wrong; check it, or calibrate it with `mlidar slam --calibrate refine`\n";
  return summary.trusted() ? 0 : 1;
}

}  // namespace

Command register_odometry(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<OdometryOptions>();
  CLI::App* sub = app.add_subcommand("odometry", "Scan-to-map odometry from all LiDARs at once (known extrinsics)");
  auto* dataset = sub->add_option("--dataset", options->dataset, "Dataset folder (dataset.yaml, times.txt, scans/)");
  auto* scans = sub->add_option("--scans", options->scans, "Folder of single-LiDAR clouds, taken in natural order");
  dataset->excludes(scans);
  add_bag_options(*sub, options->bag, true, true);
  auto* period = sub->add_option("--period", options->period, "Seconds between clouds of --scans")
                     ->check(CLI::Range(1e-6, 86400.0).description("seconds in [1e-6, 86400]"))
                     ->capture_default_str();
  sub->add_option("--times", options->times,
                  "With --scans, instead of --period: a file of one stamp per cloud (seconds, strictly increasing, '#' comments), "
                  "in the clouds' natural order")
      ->needs(scans)
      ->excludes(period);
  std::string model_names;
  for (const std::string& name : sim::lidar_model_names()) model_names += (model_names.empty() ? "" : ", ") + name;
  sub->add_option("--model", options->model,
                  "With --scans: the clouds' LiDAR (" + model_names +
                      "): rows and ranges from its vertical angles instead of recovered from each cloud")
      ->needs(scans)
      ->check(CLI::IsMember(sim::lidar_model_names()));
  sub->add_option("--lidars", options->lidars, "Comma-separated LiDAR names of the dataset (default: all)");
  sub->add_option("--threads", options->threads, "Worker threads (0: all cores)")->check(thread_count())->capture_default_str();
  add_max_base_gaps_option(*sub, options->max_base_gaps);
  sub->add_option("--config", options->config,
                  "Registration parameters: the `odometry` and `selection` sections of the YAML that `slam --config` reads "
                  "(config/mloam.yaml documents every key)");
  sub->add_option("--out", options->out,
                  "Run folder: trajectory.tum, trajectory.kitti, pose_covariance.txt, map.ply, metrics.json, run.json (a new or empty "
                  "folder, or an earlier run)")
      ->required();
  add_overwrite_flag(*sub, options->overwrite);
  return {sub, [options, &context] { return run_odometry(*options, context); }};
}

}  // namespace mlidar::cli
