// `mlidar calibrate refine`: appearance-only refinement of one LiDAR pair from
// single scans (issue 8, calib/pair_refine.hpp), from an extrinsics YAML or an
// OpenCalib initial_extrinsic.txt guess.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/mlidar/commands.hpp"
#include "mlidar/calib/pair_refine.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/opencalib.hpp"
#include "mlidar/report/pair_report.hpp"

namespace mlidar::cli {
namespace {

namespace fs = std::filesystem;

struct RefineOptions {
  std::string ref;
  std::string target;
  std::string init;
  std::string out;
  std::string report;
  std::string html;         ///< the page with the clouds overlaid before and after
  std::string ref_name;     ///< empty: the --init YAML's base, else "ref"
  std::string target_name;  ///< empty: the --init YAML's one LiDAR besides the reference, else "target"
  int target_id = 1;
  std::string search = "auto";
};

bool is_yaml(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  return ext == ".yaml" || ext == ".yml";
}

/// The guess T_ref_target and the names the output gives the pair.
struct InitialGuess {
  SE3 T_ref_target;
  std::string ref_name;
  std::string target_name;
};

/// The target in an extrinsics YAML: --target-name, else the one LiDAR besides
/// the reference (or one named "target", the old default), else an error listing them.
std::string target_in(const io::Extrinsics& extrinsics, const RefineOptions& options, const std::string& ref_name) {
  if (!options.target_name.empty()) return options.target_name;
  std::vector<std::string> others;
  std::string names;
  for (const io::LidarExtrinsic& lidar : extrinsics.lidars) {
    if (lidar.name == ref_name) continue;
    others.push_back(lidar.name);
    names += (names.empty() ? "" : ", ") + lidar.name;
  }
  if (others.size() == 1) return others.front();
  if (extrinsics.find("target") != nullptr) return "target";
  throw InputError(options.init, "lidars",
                   others.empty()
                       ? "no LiDAR besides the reference '" + ref_name + "'; the file must hold the target's guess"
                       : "several LiDARs besides the reference '" + ref_name + "' (" + names + "); name the target with --target-name");
}

/// T_ref_target from the guess file: an extrinsics YAML naming the target (and
/// the reference, or using it as base), or OpenCalib's initial_extrinsic.txt.
/// Names not given default to the YAML's base and its one other LiDAR.
InitialGuess read_initial_guess(const RefineOptions& options) {
  if (!is_yaml(options.init)) {
    const io::Extrinsics guesses = io::read_opencalib_initial_extrinsics(options.init);
    const std::string device = "device_" + std::to_string(options.target_id);
    const io::LidarExtrinsic* target = guesses.find(device);
    if (target == nullptr)
      throw InputError(options.init, "device_id", "no device " + std::to_string(options.target_id) + " (pick it with --target-id)");
    return {target->T_base_lidar, options.ref_name.empty() ? "ref" : options.ref_name,
            options.target_name.empty() ? "target" : options.target_name};
  }
  const io::Extrinsics extrinsics = io::read_extrinsics(options.init);
  const std::string ref_name = !options.ref_name.empty() ? options.ref_name : !extrinsics.base.empty() ? extrinsics.base : "ref";
  const std::string target_name = target_in(extrinsics, options, ref_name);
  if (ref_name == target_name) throw UsageError("--ref-name and --target-name must differ");
  const io::LidarExtrinsic* target = extrinsics.find(target_name);
  if (target == nullptr) throw InputError(options.init, "lidars." + target_name, "missing; name the target LiDAR with --target-name");
  const io::LidarExtrinsic* ref = extrinsics.find(ref_name);
  if (ref == nullptr && extrinsics.base != ref_name)
    throw InputError(options.init, "lidars." + ref_name, "missing; the file must name the reference LiDAR (--ref-name) or use it as base");
  return {ref == nullptr ? target->T_base_lidar : ref->T_base_lidar.inverse() * target->T_base_lidar, ref_name, target_name};
}

calib::PairSearchMode search_mode(const std::string& text) {
  if (text == "auto") return calib::PairSearchMode::kAuto;
  if (text == "always") return calib::PairSearchMode::kAlways;
  return calib::PairSearchMode::kNever;  // CLI11 checks the choice
}

nlohmann::json pose_json(const SE3& T) {
  const Vec3 rpy = rpy_deg_from_quat(T.rotation());
  const Vec4 q = quat_to_wxyz(T.rotation());
  return {{"translation", {T.translation().x(), T.translation().y(), T.translation().z()}},
          {"quaternion_wxyz", {q(0), q(1), q(2), q(3)}},
          {"rpy_deg", {rpy.x(), rpy.y(), rpy.z()}}};
}

std::vector<double> row_major(const Mat6& m) {
  std::vector<double> values;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) values.push_back(m(r, c));
  return values;
}

nlohmann::json report_json(const calib::PairRefineResult& r, double overlap_radius, double seconds) {
  nlohmann::json starts = nlohmann::json::array();
  for (const auto& s : r.starts)
    starts.push_back(
        {{"label", s.label}, {"start", pose_json(s.T_start)}, {"after", pose_json(s.T_after)}, {"overlap", s.overlap}, {"rmse_m", s.rmse}});
  return {{"verdict", std::string(calib::to_string(r.verdict))},
          {"reasons", r.reasons},
          {"searched", r.searched},
          {"chosen_start", r.chosen_start},
          {"symmetric", r.symmetric},
          {"starts", starts},
          {"T_ref_target_initial", pose_json(r.T_init)},
          {"T_ref_target", pose_json(r.T_ref_target)},
          {"covariance", row_major(r.covariance)},
          {"covariance_icp", row_major(r.covariance_icp)},
          {"information", row_major(r.information)},
          {"rotation_sd_deg", r.rotation_sd_deg},
          {"translation_sd_m", r.translation_sd_m},
          {"rmse_m", r.rmse},
          {"inlier_ratio", r.inlier_ratio},
          {"overlap",
           {{"radius_m", overlap_radius},
            {"target_fraction", r.overlap.fraction_b},
            {"ref_fraction", r.overlap.fraction_a},
            {"omega", r.overlap.omega()}}},
          {"iterations", r.iterations},
          {"seconds", seconds}};
}

void print_table(const calib::PairRefineResult& r, double seconds) {
  const auto row = [](const char* name, const SE3& T) {
    const Vec3 rpy = rpy_deg_from_quat(T.rotation());
    const Vec3& t = T.translation();
    std::printf("%-8s %9.3f %9.3f %9.3f %9.4f %9.4f %9.4f\n", name, rpy.x(), rpy.y(), rpy.z(), t.x(), t.y(), t.z());
  };
  std::printf("%-8s %9s %9s %9s %9s %9s %9s\n", "", "roll", "pitch", "yaw [deg]", "x", "y", "z [m]");
  row("initial", r.T_init);
  row("refined", r.T_ref_target);
  const SE3 change = r.T_init.inverse() * r.T_ref_target;
  std::printf("change %.3f deg, %.4f m; rmse %.4f m; overlap %.2f (omega %.3f); sd %.3f deg, %.4f m\n",
              rad_to_deg(so3_log(change.rotation()).norm()), (r.T_ref_target.translation() - r.T_init.translation()).norm(), r.rmse,
              r.overlap.fraction_b, r.overlap.omega(), r.rotation_sd_deg, r.translation_sd_m);
  std::printf("searched: %s", r.searched ? "yes" : "no");
  if (r.searched) std::printf(" (%zu starts, answer from '%s')", r.starts.size(), r.chosen_start.c_str());
  std::printf("; verdict: %s; %.2f s\n", std::string(calib::to_string(r.verdict)).c_str(), seconds);
  for (const std::string& reason : r.reasons) std::printf("  reason: %s\n", reason.c_str());
}

void write_html(const RefineOptions& options, const InitialGuess& guess, const Scan& ref, const Scan& target,
                const calib::PairRefineResult& r, double seconds) {
  report::PairCalibration pair;
  pair.command = "calibrate refine";
  pair.ref_name = guess.ref_name;
  pair.target_name = guess.target_name;
  pair.ref_file = options.ref;
  pair.target_file = options.target;
  pair.ref_points = ref.points;
  pair.target_points = target.points;
  pair.T_ref_target_before = r.T_init;
  pair.before_words = "the --init guess";
  pair.T_ref_target = r.T_ref_target;
  const bool converged = calib::is_trusted(r.verdict);
  if (converged) pair.covariance = r.covariance;
  pair.verdict_level = converged ? "ok" : "bad";
  pair.verdict = converged ? std::string(calib::to_string(r.verdict)) + ": " + options.out + " written"
                           : "not converged: " + options.out + " was not written; the overlay shows where it stopped";
  pair.reasons = r.reasons;
  char text[160];
  std::snprintf(text, sizeof text, "%.4f m over %.0f %% inliers", r.rmse, 100.0 * r.inlier_ratio);
  pair.facts.emplace_back("residual RMSE", text);
  std::snprintf(text, sizeof text, "%.2f of the target's points near the reference (omega %.3f)", r.overlap.fraction_b, r.overlap.omega());
  pair.facts.emplace_back("overlap", text);
  pair.facts.emplace_back("multi-start search",
                          r.searched ? "yes, " + std::to_string(r.starts.size()) + " starts, answer from '" + r.chosen_start + "'" : "no");
  std::snprintf(text, sizeof text, "%.2f s", seconds);
  pair.facts.emplace_back("time", text);
  const std::string html = report::render_pair_calibration_html(pair);
  io::write_atomically(options.html, [&](std::ostream& out) { out << html; });
}

int run_refine(const RefineOptions& options) {
  if (!options.ref_name.empty() && options.ref_name == options.target_name) throw UsageError("--ref-name and --target-name must differ");
  io::check_output_file(options.out, "--out");
  if (!options.report.empty()) io::check_output_file(options.report, "--report");
  if (!options.html.empty()) io::check_output_file(options.html, "--html");
  const InitialGuess guess = read_initial_guess(options);
  const SE3& T_init = guess.T_ref_target;
  const Scan ref = io::to_scan(io::read_cloud(options.ref).table, options.ref);
  const Scan target = io::to_scan(io::read_cloud(options.target).table, options.target);
  calib::PairRefineConfig config;
  config.search_mode = search_mode(options.search);

  const auto start = std::chrono::steady_clock::now();
  const calib::PairRefineResult result = calib::refine_pair(ref.points, target.points, T_init, config);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const bool trusted = calib::is_trusted(result.verdict);
  if (trusted) {
    io::Extrinsics extrinsics;
    extrinsics.base = guess.ref_name;
    extrinsics.lidars = {{guess.ref_name, SE3(), std::nullopt}, {guess.target_name, result.T_ref_target, result.covariance}};
    io::write_extrinsics(options.out, extrinsics);
  }
  if (!options.report.empty()) {
    const std::string text = report_json(result, config.overlap_radius, seconds).dump(2);
    io::write_atomically(options.report, [&](std::ostream& out) { out << text << '\n'; });
  }
  if (!options.html.empty()) write_html(options, guess, ref, target, result, seconds);
  print_table(result, seconds);
  if (!trusted) {
    std::cerr << "error: the refinement did not converge; " << options.out << " was not written"
              << (options.report.empty() ? "" : " (see the report)") << '\n';
    return static_cast<int>(ExitCode::kUntrusted);
  }
  std::cout << "wrote " << options.out << '\n';
  return 0;
}

}  // namespace

Command add_calibrate_refine(CLI::App& calibrate) {
  auto options = std::make_shared<RefineOptions>();
  CLI::App* cmd = calibrate.add_subcommand(
      "refine", "Appearance-only refinement of one LiDAR pair from single scans (point-to-plane ICP, search when far off)");
  cmd->add_option("--ref", options->ref, "Reference LiDAR scan (PCD, PLY, KITTI .bin)")->required();
  cmd->add_option("--target", options->target, "Target LiDAR scan")->required();
  cmd->add_option("--init", options->init,
                  "Initial guess of T_ref_target: an extrinsics YAML (.yaml/.yml) whose base is the reference and which "
                  "holds the target (the one other LiDAR, or --target-name); or OpenCalib initial_extrinsic.txt "
                  "(device 0 = reference, the target is --target-id)")
      ->required();
  cmd->add_option("--out", options->out,
                  "Output extrinsics YAML (reference identity, target with covariance); "
                  "written only when the refinement converged")
      ->required();
  cmd->add_option("--report", options->report, "JSON report: verdict, reasons, starts tried, overlap, covariance");
  cmd->add_option(
      "--html", options->html,
      "Page to look at: the verdict, the extrinsic with its 1-sigma and both clouds overlaid before and after (self-contained HTML)");
  cmd->add_option("--ref-name", options->ref_name,
                  "Reference LiDAR name in --init YAML and --out (default: the YAML's base; 'ref' with initial_extrinsic.txt)");
  cmd->add_option("--target-name", options->target_name,
                  "Target LiDAR name in --init YAML and --out (default: the YAML's one LiDAR besides the reference; 'target' "
                  "with initial_extrinsic.txt)");
  cmd->add_option("--target-id", options->target_id,
                  "OpenCalib device_id of the target in initial_extrinsic.txt (lidar_cloud_path.txt maps ids to clouds)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--search", options->search, "Multi-start search: auto (when the registration from the guess is poor), always, never")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "always", "never"}));
  return {cmd, [options] { return run_refine(*options); }};
}

}  // namespace mlidar::cli
