// `mlidar eval traj|calib|map`: evaluation of trajectories, extrinsics and maps
// (definitions and JSON keys in src/mlidar/eval/report.hpp). File reading and
// option checks live here; the metrics in mlidar::eval know nothing of files.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "apps/mlidar/commands.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/eval/report.hpp"
#include "mlidar/eval/svg_plot.hpp"
#include "mlidar/eval/trajectory_files.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/point_covariance_fields.hpp"
#include "mlidar/io/surface_samples.hpp"
#include "mlidar/report/eval_run.hpp"

namespace mlidar::cli {
namespace {

struct TrajOptions {
  std::string gt;
  std::string est;
  std::string format;  ///< "tum" or "kitti"; empty: from the ground truth's extension
  std::string align = "se3";
  double max_dt = 0.01;
  double delta = 1.0;
  std::string delta_unit = "frames";
  std::string json_out;
  std::string plot_out;
  std::string covariance;  ///< RUN/pose_covariance.txt: report the poses' NEES
  std::string out;         ///< a run folder: eval.json, the associated poses, report.html
  bool overwrite = false;
};

struct CalibOptions {
  std::string gt;
  std::string est;
  std::string json_out;
};

struct MapOptions {
  std::string map;
  double radius = 0.3;
  std::size_t min_neighbors = 5;
  std::string json_out;
  std::string gt_surfaces;
  double max_surface_distance = 0.5;
};

void write_json(const std::string& path, const nlohmann::json& json) {
  if (path.empty()) return;
  io::write_atomically(path, [&](std::ostream& out) { out << json.dump(2) << '\n'; });
}

int run_traj(const TrajOptions& options, const CliContext& context) {
  if (!options.json_out.empty()) io::check_output_file(options.json_out, "--json");
  if (!options.plot_out.empty()) io::check_output_file(options.plot_out, "--plot");
  eval::TrajectoryEvalOptions eval_options;
  eval_options.align = eval::parse_align_mode(options.align);
  eval_options.max_dt = options.max_dt;
  eval_options.delta = options.delta;
  eval_options.delta_unit = options.delta_unit == "m" ? eval::DeltaUnit::kMeters : eval::DeltaUnit::kFrames;
  const eval::TrajectoryFileEvaluation evaluation =
      eval::evaluate_trajectory_files({options.gt, options.est, options.format, options.covariance}, eval_options);
  const eval::TrajectoryReport& report = evaluation.report;
  std::cout << eval::format_table(report);
  if (evaluation.nees) std::cout << eval::format_table(*evaluation.nees);
  write_json(options.json_out, evaluation.json);
  if (!options.plot_out.empty()) {
    const std::string svg = eval::trajectory_plot_svg(report.gt, report.est_aligned, report.stamps, report.ate.translation_errors_m);
    io::write_atomically(options.plot_out, [&](std::ostream& out) { out << svg; });
  }
  if (!options.out.empty()) {
    std::vector<std::filesystem::path> inputs{options.gt, options.est};
    if (!options.covariance.empty()) inputs.emplace_back(options.covariance);
    report::write_eval_run(options.out, evaluation, context.run_folder(options.overwrite, inputs));
    std::cout << "wrote " << options.out << " (eval.json, report.html)\n";
  }
  return 0;
}

int run_calib(const CalibOptions& options) {
  if (!options.json_out.empty()) io::check_output_file(options.json_out, "--json");
  const io::Extrinsics gt = io::read_extrinsics(options.gt);
  const io::Extrinsics est = io::read_extrinsics(options.est);
  const auto errors = eval::evaluate_calibration(gt, est, options.est);
  std::cout << eval::format_table(errors);
  write_json(options.json_out, eval::to_json(errors));
  return 0;
}

int run_map(const MapOptions& options) {
  if (!(options.radius > 0.0)) throw UsageError("--radius must be > 0");
  if (options.min_neighbors < 4) throw UsageError("--min-neighbors must be >= 4 (a 3D covariance needs 4 points)");
  if (!options.json_out.empty()) io::check_output_file(options.json_out, "--json");
  const io::CloudFile cloud = io::read_cloud(options.map);
  const Scan scan = io::to_scan(cloud.table, options.map);
  const eval::MapMetricsOptions metrics_options{.radius = options.radius, .min_neighbors = options.min_neighbors};
  eval::MapMetrics metrics = eval::compute_map_metrics(scan.points, metrics_options);
  // The covariances belong to the points as the file holds them (to_scan drops non-finite points: a map with
  // covariances has none, so both stay aligned; the check reads the table itself).
  const auto covariances = io::read_point_covariances(cloud.table, options.map);
  if (covariances) {
    if (covariances->size() != scan.points.size())
      throw InputError(options.map, "x y z", "non-finite points in a map with covariances: every point needs a position");
    std::vector<double> traces;
    traces.reserve(covariances->size());
    for (const io::UpperCovariance& c : *covariances) traces.push_back(io::covariance_trace(c));
    metrics.covariance_trace = eval::summarize_traces(std::move(traces));
  }
  std::cout << eval::format_table(metrics, metrics_options);
  nlohmann::json json = eval::to_json(metrics, metrics_options);
  json["gt_surfaces"] = nullptr;
  if (!options.gt_surfaces.empty()) {
    const eval::SurfaceErrorOptions surface_options{.max_distance_m = options.max_surface_distance};
    const eval::SurfaceError error =
        eval::surface_error(scan.points, covariances, io::read_surface_samples(options.gt_surfaces), surface_options);
    std::cout << eval::format_table(error, surface_options);
    json["gt_surfaces"] = eval::to_json(error, surface_options);
  }
  write_json(options.json_out, json);
  return 0;
}

void add_traj(CLI::App& eval_app, std::shared_ptr<TrajOptions> options) {
  CLI::App* sub = eval_app.add_subcommand("traj", "ATE, RPE and the KITTI odometry metric of an estimated trajectory");
  sub->add_option("--gt", options->gt, "Ground-truth trajectory (TUM or KITTI poses)")->required();
  sub->add_option("--est", options->est, "Estimated trajectory, same format")->required();
  sub->add_option("--format", options->format, "tum or kitti (default: kitti for a .kitti ground truth, else tum)")
      ->check(CLI::IsMember({"tum", "kitti"}));
  sub->add_option("--align", options->align, "Alignment before ATE: se3 (Horn), sim3 (Umeyama), origin, none")
      ->check(CLI::IsMember({"se3", "sim3", "origin", "none"}))
      ->capture_default_str();
  sub->add_option("--max-dt", options->max_dt, "Largest stamp difference (s) of associated poses (TUM)")->capture_default_str();
  sub->add_option("--delta", options->delta, "RPE step")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--delta-unit", options->delta_unit, "RPE step unit: frames or m")
      ->check(CLI::IsMember({"frames", "m"}))
      ->capture_default_str();
  sub->add_option("--json", options->json_out, "Write the metrics as JSON to this file");
  sub->add_option("--plot", options->plot_out, "Write an SVG plot (top view and ATE over time) to this file");
  sub->add_option("--covariance", options->covariance,
                  "The run's pose_covariance.txt: also report the poses' NEES against the ground truth (aligned at the first pose)");
  sub->add_option("--out", options->out,
                  "Run folder: eval.json, groundtruth.tum and trajectory.tum (the associated poses), report.html with the error over "
                  "time and the KITTI drift per segment length, run.json (a new or empty folder, or an earlier run)");
  add_overwrite_flag(*sub, options->overwrite);
}

void add_calib(CLI::App& eval_app, std::shared_ptr<CalibOptions> options) {
  CLI::App* sub = eval_app.add_subcommand("calib", "Rotation/translation error and NEES of estimated extrinsics");
  sub->add_option("--gt", options->gt, "Ground-truth extrinsics YAML")->required();
  sub->add_option("--est", options->est, "Estimated extrinsics YAML (covariances give the NEES)")->required();
  sub->add_option("--json", options->json_out, "Write the metrics as JSON to this file");
}

void add_map(CLI::App& eval_app, std::shared_ptr<MapOptions> options) {
  CLI::App* sub = eval_app.add_subcommand("map", "Mean map entropy and mean plane variance of a point cloud");
  sub->add_option("--map", options->map, "Map point cloud (PLY, PCD or .bin)")->required();
  sub->add_option("--radius", options->radius, "Neighbourhood radius (m)")->check(CLI::Range(1e-6, 1e6))->capture_default_str();
  sub->add_option("--min-neighbors", options->min_neighbors, "Fewest neighbours (self included) for a point to count")
      ->capture_default_str();
  sub->add_option("--json", options->json_out, "Write the metrics as JSON to this file");
  sub->add_option("--gt-surfaces", options->gt_surfaces,
                  "True surfaces (x y z nx ny nz PLY, e.g. a simulated dataset's groundtruth/surfaces.ply) in the map's frame: each "
                  "point's distance to them and, with point covariances, its normalized error");
  sub->add_option("--max-surface-distance", options->max_surface_distance,
                  "Map points farther than this (m) from the true surfaces are not matched")
      ->check(CLI::Range(1e-6, 1e6))
      ->capture_default_str();
}

}  // namespace

Command register_eval(CLI::App& app, const CliContext& context) {
  CLI::App* sub = app.add_subcommand("eval", "Evaluate trajectories, extrinsics, maps and 3D detections (evo / KITTI definitions)");
  sub->require_subcommand(1);
  auto traj = std::make_shared<TrajOptions>();
  auto calib = std::make_shared<CalibOptions>();
  auto map = std::make_shared<MapOptions>();
  add_traj(*sub, traj);
  add_calib(*sub, calib);
  add_map(*sub, map);
  const Command detections = add_eval_detections(*sub);
  return {sub, [sub, traj, calib, map, detections, &context] {
            if (sub->got_subcommand(detections.sub)) return detections.run();
            if (sub->got_subcommand("traj")) return run_traj(*traj, context);
            if (sub->got_subcommand("calib")) return run_calib(*calib);
            return run_map(*map);
          }};
}

}  // namespace mlidar::cli
