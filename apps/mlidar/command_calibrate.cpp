// `mlidar calibrate planes`: PS-Calib (thesis Chap. 2) from one scan of each
// LiDAR looking at a wall corner. `mlidar calibrate auto`: Auto-Calib (thesis
// Chap. 3) from a dataset folder's motion. `calibrate` is the parent of the solvers.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "apps/mlidar/bag_options.hpp"
#include "apps/mlidar/commands.hpp"
#include "mlidar/calib/planes_calibrator.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/pipelines/autocalib_config.hpp"
#include "mlidar/pipelines/autocalib_job.hpp"
#include "mlidar/pipelines/planes_job.hpp"
#include "mlidar/report/pair_report.hpp"
#include "mlidar/report/run_report.hpp"

namespace mlidar::cli {
namespace {

struct PlanesOptions {
  std::string ref;
  std::string target;
  std::string init;
  std::string config;
  std::string out;
  std::string report;
  std::string html;  ///< the page with the clouds overlaid before and after
  bool strict = false;
};

void write_planes_html(const PlanesOptions& options, const pipelines::PlanesJobResult& job) {
  const calib::PlanesResult& result = job.result;
  const std::string& ref_name = job.ref_name;
  const std::string& target_name = job.target_name;
  report::PairCalibration pair;
  pair.command = "calibrate planes";
  pair.ref_name = ref_name;
  pair.target_name = target_name;
  pair.ref_file = options.ref;
  pair.target_file = options.target;
  pair.ref_points = job.ref.points;
  pair.target_points = job.target.points;
  pair.T_ref_target_before = job.guess.value_or(SE3());
  pair.before_words = job.guess ? "the --init guess" : "identity (no --init: the clouds as recorded)";
  pair.T_ref_target = result.T_ref_target;
  pair.covariance = result.covariance;
  pair.verdict_level = result.ok() ? "ok" : "warn";
  pair.verdict = result.ok() ? "ok: three planes found in both clouds, " + options.out + " written"
                             : "written with warnings (" + options.out + "): check the overlay before using it";
  for (const auto w : result.warnings) pair.reasons.emplace_back(calib::warning_name(w));
  char text[160];
  std::snprintf(text, sizeof text, "%.4f m, %d iterations%s", result.residual_sigma, result.iterations,
                result.converged ? "" : " (not converged)");
  pair.facts.emplace_back("residual sigma", text);
  for (const auto* cloud : {&result.ref, &result.target}) {
    std::snprintf(text, sizeof text, "%zu planes found; corner angles %.1f, %.1f, %.1f deg", cloud->planes_found, cloud->angles_deg[0],
                  cloud->angles_deg[1], cloud->angles_deg[2]);
    pair.facts.emplace_back(cloud == &result.ref ? ref_name : target_name, text);
  }
  std::snprintf(text, sizeof text, "%.2f s", job.seconds);
  pair.facts.emplace_back("time", text);
  const std::string html = report::render_pair_calibration_html(pair);
  io::write_atomically(options.html, [&](std::ostream& out) { out << html; });
}

int run_planes(const PlanesOptions& options) {
  io::check_output_file(options.out, "--out");
  if (!options.report.empty()) io::check_output_file(options.report, "--report");
  if (!options.html.empty()) io::check_output_file(options.html, "--html");
  const pipelines::PlanesJobResult job = pipelines::run_planes_job({options.ref, options.target, options.init, options.config});
  const calib::PlanesResult& result = job.result;
  io::write_extrinsics(options.out, pipelines::planes_extrinsics(job));
  if (!options.report.empty()) {
    const std::string text = pipelines::planes_report_json(job).dump(2);
    io::write_atomically(options.report, [&](std::ostream& out) { out << text << '\n'; });
  }
  if (!options.html.empty()) write_planes_html(options, job);
  const Vec3& t = result.T_ref_target.translation();
  std::cout << "T_ref_target t = [" << t.x() << ", " << t.y() << ", " << t.z() << "] m, residual sigma " << result.residual_sigma << " m, "
            << result.iterations << " iterations, " << job.seconds << " s\n";
  std::cout << "verdict: " << (result.ok() ? "ok" : "warning");
  for (const auto w : result.warnings) std::cout << ' ' << calib::warning_name(w);
  std::cout << '\n';
  return options.strict && !result.ok() ? static_cast<int>(ExitCode::kUntrusted) : 0;
}

struct AutoOptions {
  std::string dataset;
  BagCliOptions bag;
  std::string base;
  std::string stage = "all";
  std::string init;
  std::string config;
  int pair_stride = 5;
  int threads = 0;
  double max_base_gaps = pipelines::kDefaultMaxBaseGaps;
  bool overwrite = false;
  std::string out;
};

std::string pose_columns(const SE3& T) {
  const Vec3 t = T.translation();
  const Vec3 rpy = rpy_deg_from_quat(T.rotation());
  char text[96];
  std::snprintf(text, sizeof text, "%8.4f %8.4f %8.4f %8.3f %8.3f %8.3f", t.x(), t.y(), t.z(), rpy.x(), rpy.y(), rpy.z());
  return text;
}

std::string refine_column(const pipelines::LidarCalibration& c) {
  if (!c.refine) return "-";
  const auto& r = *c.refine;
  if (r.fusion) return std::string(pipelines::to_string(r.verdict)) + " fused " + std::to_string(r.candidates.size());
  return std::string(pipelines::to_string(r.verdict)) + " " + std::to_string(r.average.kept.size()) + "/" +
         std::to_string(r.candidates.size());
}

/// One row per LiDAR: hand-eye's estimate and the refined one side by side (t [m], roll pitch yaw [deg]), in the frame of
/// extrinsics.yaml.
void print_auto_table(const pipelines::AutoCalibSummary& summary) {
  std::printf("%-8s %-20s %-14s %-53s %-53s %9s %9s\n", "lidar", "hand-eye", "refine kept", "hand-eye t [m] rpy [deg]",
              "final t [m] rpy [deg]", "sd_t [m]", "sd_r [deg]");
  for (const auto& c : summary.lidars) {
    const bool is_base = c.name == summary.base;
    std::string handeye = is_base ? "base" : "-";
    if (!is_base && c.handeye_ran) handeye = std::string(calib::to_string(c.hand_eye.verdict)) + (c.ground ? "+ground" : "");
    const pipelines::BaseFrame& frame = summary.frame;
    const std::string handeye_pose = c.handeye_ran ? pose_columns(frame.extrinsic_to_base(c.T_base_lidar_handeye)) : "-";
    if (!c.usable) {
      std::printf("%-8s %-20s %-14s %-53s %-53s %9s %9s\n", c.name.c_str(), handeye.c_str(), refine_column(c).c_str(), handeye_pose.c_str(),
                  "not calibrated", "-", "-");
      continue;
    }
    const double sd_t = std::sqrt(c.covariance.topLeftCorner<3, 3>().trace());  // the trace is the same in either frame
    const double sd_r = rad_to_deg(std::sqrt(c.covariance.bottomRightCorner<3, 3>().trace()));
    const SE3 final_pose = is_base ? frame.T_base_reference : frame.extrinsic_to_base(c.T_base_lidar);
    std::printf("%-8s %-20s %-14s %-53s %-53s %9.4f %9.4f\n", c.name.c_str(), handeye.c_str(), refine_column(c).c_str(),
                handeye_pose.c_str(), pose_columns(final_pose).c_str(), sd_t, sd_r);
  }
}

int run_auto(const AutoOptions& options, bool pair_stride_given, const CliContext& context) {
  io::RunFolder run(options.out, "calibrate auto",
                    context.run_folder(options.overwrite, {options.dataset.empty() ? options.bag.bag : options.dataset}));
  pipelines::AutoCalibJob job;
  if (!options.config.empty()) job = pipelines::apply_autocalib_config(io::read_file_text(options.config), options.config, job);
  job.dataset = options.dataset;
  job.bag = options.bag.bag;
  BagCliOptions bag = options.bag;
  bag.base = options.base;  // --base names the base LiDAR of the bag too
  job.bag_options = bag_source_options(bag);
  job.base = options.base;
  job.stage = options.stage == "handeye"  ? pipelines::AutoCalibStage::handeye
              : options.stage == "refine" ? pipelines::AutoCalibStage::refine
                                          : pipelines::AutoCalibStage::all;  // CLI11 checks the choice
  job.init = options.init;
  if (pair_stride_given) job.pair_stride = options.pair_stride;
  job.threads = options.threads;
  job.max_base_gaps = options.max_base_gaps;
  job.out = run.path();
  const auto summary = pipelines::run_autocalib_job(job);
  report::write_run_report(run.path(), {"calibrate auto", options.dataset, options.out});
  run.commit();
  print_auto_table(summary);
  std::cout << "wrote " << options.out << " (extrinsics.yaml, calibration.json) in " << summary.seconds << " s\n";
  for (const auto& line : summary.gaps) std::cerr << "warning: " << line << "; see calibration.json skipped_scans\n";
  if (summary.base_failure) {
    std::cerr << "error: " << *summary.base_failure << '\n';
    return static_cast<int>(ExitCode::kUntrusted);
  }
  for (const auto& c : summary.lidars) {
    if (c.usable) continue;
    std::cerr << "error: " << c.name << " not calibrated: " << c.reason << "\n  try: " << c.advice << "\n  extrinsics.yaml "
              << (c.given ? "keeps its input extrinsic, without a covariance" : "leaves it out") << '\n';
  }
  if (!summary.all_usable()) {
    std::cerr << "error: a LiDAR could not be calibrated (see calibration.json: handeye / refine verdict, message)\n";
    return static_cast<int>(ExitCode::kUntrusted);
  }
  return 0;
}

}  // namespace

Command register_calibrate(CLI::App& app, const CliContext& context) {
  CLI::App* sub = app.add_subcommand("calibrate", "Calibrate LiDAR extrinsics");
  sub->require_subcommand(1);
  auto planes = std::make_shared<PlanesOptions>();
  CLI::App* planes_cmd = sub->add_subcommand("planes", "One-shot calibration from a wall corner seen by two LiDARs");
  planes_cmd->add_option("--ref", planes->ref, "Reference LiDAR cloud (PCD, PLY, KITTI .bin)")->required();
  planes_cmd->add_option("--target", planes->target, "Target LiDAR cloud")->required();
  planes_cmd->add_option("--init", planes->init, "Rough extrinsics YAML naming both LiDARs (picks the plane matching)");
  planes_cmd->add_option("--config", planes->config, "planes.yaml with PlanesConfig keys");
  planes_cmd->add_option("--out", planes->out, "Output extrinsics YAML (T_ref_target with covariance)")->required();
  planes_cmd->add_option("--report", planes->report, "JSON report: planes, angles, residuals, verdict");
  planes_cmd->add_option(
      "--html", planes->html,
      "Page to look at: the verdict, the extrinsic with its 1-sigma and both clouds overlaid before and after (self-contained HTML)");
  planes_cmd->add_flag("--strict", planes->strict, "Exit 1 when the verdict carries a warning");
  auto autocal = std::make_shared<AutoOptions>();
  CLI::App* auto_cmd =
      sub->add_subcommand("auto", "Target-less calibration of every LiDAR: hand-eye from motion, then appearance refinement");
  auto_cmd->add_option("--dataset", autocal->dataset, "Dataset folder (dataset.yaml, times.txt, scans/)");
  add_bag_options(*auto_cmd, autocal->bag, true, false);
  auto_cmd->add_option("--base", autocal->base, "Base LiDAR (default: the dataset's base)");
  auto_cmd->add_option("--stage", autocal->stage, "Stages: handeye, refine (needs --init) or all (hand-eye then refine)")
      ->check(CLI::IsMember({"handeye", "refine", "all"}))
      ->capture_default_str();
  auto_cmd->add_option("--init", autocal->init,
                       "Starting extrinsics YAML: the start of --stage refine; with all, used only where hand-eye fails");
  auto_cmd->add_option("--config", autocal->config, "auto.yaml with the stage parameters (pair_stride, handeye, refine)");
  CLI::Option* stride =
      auto_cmd->add_option("--pair-stride", autocal->pair_stride, "Frames between the ends of a motion pair (overrides --config)")
          ->check(CLI::Range(1, 1000000))
          ->capture_default_str();
  auto_cmd->add_option("--threads", autocal->threads, "Worker threads (0: all cores)")->check(thread_count())->capture_default_str();
  add_max_base_gaps_option(*auto_cmd, autocal->max_base_gaps);
  auto_cmd
      ->add_option("--out", autocal->out,
                   "Run folder: extrinsics.yaml, calibration.json, run.json (a new or empty folder, or an earlier run)")
      ->required();
  add_overwrite_flag(*auto_cmd, autocal->overwrite);
  const Command refine = add_calibrate_refine(*sub);
  auto planes_run = [planes] { return run_planes(*planes); };
  auto auto_run = [autocal, stride, &context] { return run_auto(*autocal, stride->count() > 0, context); };
  return {sub, [sub, planes_cmd, planes_run, auto_run, refine] {
            if (sub->got_subcommand(refine.sub)) return refine.run();
            return sub->got_subcommand(planes_cmd) ? planes_run() : auto_run();
          }};
}

}  // namespace mlidar::cli
