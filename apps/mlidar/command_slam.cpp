// `mlidar slam`: the M-LOAM back end: odometry with online extrinsic calibration of every LiDAR.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "apps/mlidar/bag_options.hpp"
#include "apps/mlidar/commands.hpp"
#include "apps/mlidar/progress_bar.hpp"
#include "mlidar/calib/extrinsic_check.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"
#include "mlidar/pipelines/slam_job.hpp"
#include "mlidar/report/run_report.hpp"

namespace mlidar::cli {
namespace {

/// One line per auxiliary LiDAR: where its calibration stands, and the directions the motion left unobservable.
void print_lidar(const pipelines::SlamLidarReport& lidar) {
  std::cout << "  " << lidar.name << ": " << pipelines::to_string(lidar.role);
  if (lidar.initialized_frame) std::cout << ", initialized at frame " << *lidar.initialized_frame;
  if (lidar.initialization.planar_motion) std::cout << " (planar motion)";
  const auto& sv = lidar.initialization.singular_values;
  if (lidar.role == pipelines::LidarRole::initializing && lidar.initialization.pairs_stored >= 10 && sv[2] < 0.1 * sv[1]) {
    const double sigma_m = lidar.initialization.translation_std_m;
    if (sigma_m > 0.0)  // the planar start (eq 3.10-3.12) was solved but refused
      std::cout << " (the rotations share one axis; the start from its own translations is too uncertain, predicted 1-sigma "
                << std::lround(sigma_m * 100.0) << " cm above initialization.translation_max_std_m: more turning, or "
                << "`mlidar calibrate auto`, which registers against the base's map over the whole drive)";
    else
      std::cout << " (the rotations share one axis: the rotation about it is unobservable by hand-eye; try --calibrate refine)";
  }
  if (lidar.translation_start == pipelines::TranslationStart::zero) std::cout << " (translation not solvable from motion: started from 0)";
  if (lidar.translation_start == pipelines::TranslationStart::appearance)
    std::cout << " (started from its appearance against the base's map: hand-eye had not started it)";
  if (lidar.converged_frame) std::cout << ", converged at frame " << *lidar.converged_frame;
  if (lidar.restarts > 0) std::cout << ", " << lidar.restarts << " re-calibration(s) after an extrinsic shock";
  if (lidar.missing_frames > 0) std::cout << ", " << lidar.missing_frames << " frame(s) without a scan";
  std::cout << '\n';
  if (lidar.role == pipelines::LidarRole::initializing && !lidar.appearance_attempts.empty()) {
    const pipelines::AppearanceAttempt& last = lidar.appearance_attempts.back();
    std::cout << "    appearance start at frame " << last.frame << " (" << lidar.appearance_attempts.size() << " attempt(s), "
              << last.frames_used << " frames, " << (last.searched ? "with" : "without") << " search): " << last.verdict << ", "
              << last.message
              << "; tried again every initialization.appearance_after_frames frames; else `--calibrate refine` from the dataset's "
                 "extrinsics, or `mlidar calibrate auto` over the whole drive\n";
  }
  if (lidar.restarts == 0 && !lidar.reinitialization_frames.empty())
    std::cout << "    re-initialized " << lidar.reinitialization_frames.size()
              << " time(s): its window residuals stayed high against the map\n";
  for (const auto& direction : lidar.unobservable_from_motion) {
    const bool observed = lidar.converged_frame.has_value() || lidar.accepted > 0;
    std::cout << "    unobservable from motion: " << direction << "; "
              << (observed ? "observed by the calibration window (accepted against the map)" : "not yet observed by the calibration window")
              << '\n';
  }
  if (lidar.axis_translation_source != pipelines::AxisTranslationSource::none)
    std::cout << "    translation along the axis at the start: " << pipelines::to_string(lidar.axis_translation_source) << '\n';
  for (const auto& weak : lidar.weak)
    std::cout << "    weakly observed: " << weak.description << " (information " << weak.eigenvalue << ")\n";
}

/// A given extrinsic that disagreed with the map (calib::ExtrinsicCheck), in words; empty when none did.
std::string disagreement_warning(const pipelines::SlamLidarReport& lidar) {
  if (!lidar.disagreement) return "";
  const pipelines::ExtrinsicDisagreement& d = *lidar.disagreement;
  std::ostringstream text;
  text << std::setprecision(2) << std::fixed;
  text << "warning: " << lidar.name << ": the given extrinsic disagrees with the map ("
       << calib::describe({.frame = d.frame, .residual_ratio = d.residual_ratio, .map_ratio = d.map_ratio, .frames_lost = d.frames_lost})
       << "); ";
  if (!d.recalibrated) {
    text << "the run used it as given, its trajectory and map may be wrong: check it, or run --calibrate refine\n";
    return text.str();
  }
  text << "calibrated online from it instead";
  if (d.from_first_frame) text << ", the run started again from the first frame";
  if (d.after_shock) text << " from there on (after its extrinsic shock: the mounting moved during the run)";
  if (lidar.role == pipelines::LidarRole::trusted) {
    const SE3 T_given_current = lidar.given_T_base_lidar.inverse() * lidar.T_base_lidar;
    text << ": converged at frame " << lidar.converged_frame.value_or(0) << ", "
         << rad_to_deg(Eigen::AngleAxisd(T_given_current.rotation()).angle()) << " deg / " << T_given_current.translation().norm()
         << " m from the given one (extrinsics.yaml); fix the extrinsics file\n";
  } else {
    text << ": it did not converge (its extrinsic in extrinsics.yaml has no covariance)\n";
  }
  return text.str();
}

struct SlamOptions {
  pipelines::SlamJob job;
  BagCliOptions bag;
  std::string calibrate = "online";
  bool overwrite = false;
};

pipelines::ExtrinsicSource extrinsic_source(const std::string& name) {
  if (name == "fixed") return pipelines::ExtrinsicSource::fixed;
  return name == "refine" ? pipelines::ExtrinsicSource::refine : pipelines::ExtrinsicSource::online;  // CLI11 checks the choice
}

int run_slam(SlamOptions options, const CliContext& context) {
  io::RunFolder run(
      options.job.out, "slam",
      context.run_folder(options.overwrite, {options.job.dataset.empty() ? std::filesystem::path(options.bag.bag) : options.job.dataset}));
  pipelines::SlamJob job = options.job;
  job.bag = options.bag.bag;
  job.bag_options = bag_source_options(options.bag);
  if (job.bag.empty()) job.extrinsics = options.bag.extrinsics;  // a dataset's extrinsics replaced (a bag's: bag_options)
  job.calibrate = extrinsic_source(options.calibrate);
  job.out = run.path();
  const auto summary = pipelines::run_slam_job(job, terminal_progress_bar());
  report::write_run_report(run.path(), {"slam", options.job.dataset, options.job.out});
  run.commit();
  std::cout << "wrote " << options.job.out.string() << ": " << summary.frames << " frames, " << summary.mean_frame_seconds * 1e3
            << " ms per frame, " << summary.lost_frames << " lost, " << summary.suspect_frames.size() << " suspect\n";
  for (const auto& lidar : summary.lidars) print_lidar(lidar);
  std::cout << "note: " << pipelines::last_pose_note(summary.last_pose_covariance, summary.lost_at_end) << '\n';
  if (!summary.all_converged())
    std::cerr
        << "warning: some LiDAR's calibration did not converge; its extrinsic in extrinsics.yaml has no covariance (see metrics.json)\n";
  std::cerr << suspect_frames_warning(summary.suspect_frames);
  std::cerr << summary.map_restart_warning;
  if (summary.lost_frames > 0) std::cerr << "warning: " << summary.lost_frames << " frame(s) could not be registered; see metrics.json\n";
  for (const auto& line : summary.gaps) std::cerr << "warning: " << line << "; see metrics.json skipped_scans\n";
  if (summary.base_failure) std::cerr << "error: " << *summary.base_failure << '\n';
  for (const auto& lidar : summary.lidars) std::cerr << disagreement_warning(lidar);
  return summary.trusted() ? 0 : 1;
}

}  // namespace

Command register_slam(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<SlamOptions>();
  pipelines::SlamJob* job = &options->job;
  CLI::App* sub = app.add_subcommand("slam", "Multi-LiDAR odometry with online extrinsic calibration (M-LOAM back end)");
  sub->add_option("--dataset", job->dataset, "Dataset folder (dataset.yaml, times.txt, scans/)");
  add_bag_options(*sub, options->bag, true, true);
  sub->add_option("--config", job->config, "Back-end parameters (config/mloam.yaml documents every key; default Table 4.2)");
  sub->add_option(
         "--calibrate", options->calibrate,
         "online: initialize and calibrate every LiDAR online; refine: calibrate from the dataset's extrinsics; fixed: use them as given")
      ->check(CLI::IsMember({"online", "refine", "fixed"}))
      ->capture_default_str();
  sub->add_option("--threads", job->threads, "Worker threads (0: all cores)")->check(thread_count())->capture_default_str();
  add_max_base_gaps_option(*sub, job->max_base_gaps);
  sub->add_option("--out", job->out,
                  "Run folder: trajectory.tum/.kitti, pose_covariance.txt, extrinsics.yaml, map.ply, metrics.json, report.html, run.json "
                  "(a new or empty folder, or an "
                  "earlier run)")
      ->required();
  add_overwrite_flag(*sub, options->overwrite);
  return {sub, [options, &context] { return run_slam(*options, context); }};
}

}  // namespace mlidar::cli
