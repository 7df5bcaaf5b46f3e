// The jobs that write a run folder, as the CLI runs them: odometry, slam and calibrate auto. Each stages its
// run folder, writes report.html and commits (io/run_folder.hpp); the GIL is released while the job runs.
// What they return is the job's summary; the package (python/mlidar/__init__.py) adds the folder's files.
#include <optional>
#include <string>
#include <vector>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "array_views.hpp"
#include "bindings.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/bag_frames.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/run_folder.hpp"
#include "mlidar/pipelines/autocalib_config.hpp"
#include "mlidar/pipelines/autocalib_job.hpp"
#include "mlidar/pipelines/odometry_job.hpp"
#include "mlidar/pipelines/slam_job.hpp"
#include "mlidar/report/run_report.hpp"
#include "mlidar/sim/lidar_models.hpp"

namespace mlidar::python {
namespace {

/// Where a run comes from and goes to, as the CLI's shared options say it.
struct RunOptions {
  std::filesystem::path out;
  bool overwrite = false;
  std::vector<std::string> arguments;  ///< what run.json records as the command line
};

io::RunFolderOptions folder_options(const RunOptions& run, const std::filesystem::path& input) {
  return {run.overwrite, {input}, run.arguments};
}

/// The summary's fields shared by the trajectory jobs.
template <typename Summary>
py::dict trajectory_summary(const Summary& summary, const std::filesystem::path& out) {
  py::dict result;
  result["out"] = out.string();
  result["frames"] = summary.frames;
  result["lost_frames"] = summary.lost_frames;
  result["map_restarts"] = summary.map_restarts;
  result["suspect_frames"] = summary.suspect_frames;
  result["mean_frame_seconds"] = summary.mean_frame_seconds;
  result["trajectory"] = trajectory_array(summary.trajectory);
  result["gaps"] = summary.gaps;
  result["base_failure"] = summary.base_failure ? py::object(py::str(*summary.base_failure)) : py::object(py::none());
  result["last_pose_covariance"] = dense_array(summary.last_pose_covariance);
  return result;
}

std::filesystem::path input_of(const std::filesystem::path& dataset, const std::filesystem::path& scans, const io::BagArguments& bag) {
  if (!dataset.empty()) return dataset;
  return !scans.empty() ? scans : std::filesystem::path(bag.bag);
}

py::dict run_odometry(const RunOptions& run_options, const std::filesystem::path& dataset, const std::filesystem::path& scans,
                      const io::BagArguments& bag, double period, const std::optional<std::filesystem::path>& times,
                      const std::string& model, const std::vector<std::string>& lidars, int threads, double max_base_gaps,
                      const std::filesystem::path& config, const py::object& progress) {
  const int given = int{!dataset.empty()} + int{!scans.empty()} + int{!bag.bag.empty()};
  if (given != 1) throw UsageError("odometry: give exactly one of dataset, scans and bag");
  if (times && scans.empty()) throw UsageError("odometry: times goes with scans");
  const std::function<void(int, int)> report_progress = progress_function(progress);
  pipelines::OdometryJobSummary summary;
  std::filesystem::path out;
  {
    py::gil_scoped_release release;
    io::RunFolder run(run_options.out, "odometry", folder_options(run_options, input_of(dataset, scans, bag)));
    pipelines::OdometryJob job;
    job.dataset = dataset;
    job.scans = scans;
    job.bag = bag.bag;
    job.bag_options = io::bag_source_options(bag);
    job.period = period;
    job.times = times;
    if (!model.empty()) job.scan_model = sim::lidar_model(model);
    job.lidars = lidars;
    job.threads = threads;
    job.max_base_gaps = max_base_gaps;
    job.config = config;
    if (job.bag.empty()) job.extrinsics = bag.extrinsics;
    job.out = run.path();
    summary = pipelines::run_odometry_job(job, report_progress);
    report::write_run_report(run.path(), {"odometry", dataset, run_options.out});
    run.commit();
    out = run.out();
  }
  py::dict result = trajectory_summary(summary, out);
  result["degenerate_frames"] = summary.degenerate_frames;
  result["front_end"] = summary.front_end;
  result["exit_code"] = summary.trusted() ? 0 : 1;
  return result;
}

pipelines::ExtrinsicSource extrinsic_source(const std::string& name) {
  if (name == "online") return pipelines::ExtrinsicSource::online;
  if (name == "refine") return pipelines::ExtrinsicSource::refine;
  if (name == "fixed") return pipelines::ExtrinsicSource::fixed;
  throw UsageError("--calibrate is '" + name + "': use online, refine or fixed");
}

py::dict run_slam(const RunOptions& run_options, const std::filesystem::path& dataset, const io::BagArguments& bag,
                  const std::filesystem::path& config, const std::string& calibrate, int threads, double max_base_gaps,
                  const py::object& progress) {
  if (dataset.empty() == bag.bag.empty()) throw UsageError("slam: give exactly one of dataset and bag");
  const std::function<void(int, int)> report_progress = progress_function(progress);
  pipelines::SlamJobSummary summary;
  std::filesystem::path out;
  {
    py::gil_scoped_release release;
    io::RunFolder run(run_options.out, "slam", folder_options(run_options, input_of(dataset, {}, bag)));
    pipelines::SlamJob job;
    job.dataset = dataset;
    job.bag = bag.bag;
    job.bag_options = io::bag_source_options(bag);
    if (job.bag.empty()) job.extrinsics = bag.extrinsics;
    job.config = config;
    job.calibrate = extrinsic_source(calibrate);
    job.threads = threads;
    job.max_base_gaps = max_base_gaps;
    job.out = run.path();
    summary = pipelines::run_slam_job(job, report_progress);
    report::write_run_report(run.path(), {"slam", dataset, run_options.out});
    run.commit();
    out = run.out();
  }
  py::dict result = trajectory_summary(summary, out);
  py::list lidars;
  for (const pipelines::SlamLidarReport& lidar : summary.lidars) {
    py::dict entry;
    entry["name"] = lidar.name;
    entry["role"] = std::string(pipelines::to_string(lidar.role));
    entry["converged_frame"] = lidar.converged_frame ? py::object(py::int_(*lidar.converged_frame)) : py::object(py::none());
    lidars.append(entry);
  }
  result["lidars"] = lidars;
  result["all_converged"] = summary.all_converged();
  result["extrinsic_disagreed"] = summary.extrinsic_disagreed();
  result["exit_code"] = summary.trusted() ? 0 : 1;
  return result;
}

pipelines::AutoCalibStage autocalib_stage(const std::string& name) {
  if (name == "all") return pipelines::AutoCalibStage::all;
  if (name == "handeye") return pipelines::AutoCalibStage::handeye;
  if (name == "refine") return pipelines::AutoCalibStage::refine;
  throw UsageError("--stage is '" + name + "': use handeye, refine or all");
}

py::dict run_calibrate_auto(const RunOptions& run_options, const std::filesystem::path& dataset, io::BagArguments bag,
                            const std::string& base, const std::string& stage, const std::filesystem::path& init,
                            const std::filesystem::path& config, std::optional<int> pair_stride, int threads, double max_base_gaps,
                            const py::object& progress) {
  if (dataset.empty() == bag.bag.empty()) throw UsageError("calibrate_auto: give exactly one of dataset and bag");
  if (pair_stride && *pair_stride < 1) throw UsageError("--pair-stride is " + std::to_string(*pair_stride) + ": use 1 or more");
  const std::function<void(int, int)> report_progress = progress_function(progress);
  pipelines::AutoCalibSummary summary;
  std::filesystem::path out;
  {
    py::gil_scoped_release release;
    io::RunFolder run(run_options.out, "calibrate auto", folder_options(run_options, input_of(dataset, {}, bag)));
    pipelines::AutoCalibJob job;
    if (!config.empty()) job = pipelines::apply_autocalib_config(io::read_file_text(config), config.string(), job);
    job.dataset = dataset;
    job.bag = bag.bag;
    bag.base = base;  // names the base LiDAR of a bag too, as --base
    job.bag_options = io::bag_source_options(bag);
    job.base = base;
    job.stage = autocalib_stage(stage);
    job.init = init;
    if (pair_stride) job.pair_stride = *pair_stride;
    job.threads = threads;
    job.max_base_gaps = max_base_gaps;
    job.out = run.path();
    summary = pipelines::run_autocalib_job(job, [&](const std::string&, int done, int total) { report_progress(done, total); });
    report::write_run_report(run.path(), {"calibrate auto", dataset, run_options.out});
    run.commit();
    out = run.out();
  }
  py::dict result;
  result["out"] = out.string();
  result["base"] = summary.base;
  result["seconds"] = summary.seconds;
  py::list lidars;
  for (const pipelines::LidarCalibration& lidar : summary.lidars) {
    py::dict entry;
    entry["name"] = lidar.name;
    entry["usable"] = lidar.usable;
    entry["reason"] = lidar.reason;
    entry["advice"] = lidar.advice;
    lidars.append(entry);
  }
  result["lidars"] = lidars;
  result["gaps"] = summary.gaps;
  result["base_failure"] = summary.base_failure ? py::object(py::str(*summary.base_failure)) : py::object(py::none());
  result["exit_code"] = summary.base_failure || !summary.all_usable() ? 1 : 0;
  return result;
}

io::BagArguments bag_arguments(const std::string& bag, const std::string& topics, const std::string& stamp_at,
                               const std::string& extrinsics, const std::string& models, double start, double duration) {
  return {bag, topics, "", stamp_at, extrinsics, models, start, duration};
}

}  // namespace

void add_jobs(py::module_& module) {
  module.def(
      "odometry",
      [](const std::filesystem::path& out, const std::filesystem::path& dataset, const std::filesystem::path& scans, const std::string& bag,
         double period, const std::optional<std::filesystem::path>& times, const std::string& model, const std::vector<std::string>& lidars,
         int threads, double max_base_gaps, const std::filesystem::path& config, const std::string& extrinsics, const std::string& topics,
         const std::string& base, const std::string& stamp_at, const std::string& models, double start, double duration, bool overwrite,
         const py::object& progress, const std::vector<std::string>& arguments) {
        io::BagArguments bag_options = bag_arguments(bag, topics, stamp_at, extrinsics, models, start, duration);
        bag_options.base = base;
        return run_odometry({out, overwrite, arguments}, dataset, scans, bag_options, period, times, model, lidars, threads, max_base_gaps,
                            config, progress);
      },
      py::kw_only(), py::arg("out"), py::arg("dataset") = "", py::arg("scans") = "", py::arg("bag") = "", py::arg("period") = 0.1,
      py::arg("times") = py::none(), py::arg("model") = "", py::arg("lidars") = std::vector<std::string>{}, py::arg("threads") = 0,
      py::arg("max_base_gaps") = pipelines::kDefaultMaxBaseGaps, py::arg("config") = "", py::arg("extrinsics") = "", py::arg("topics") = "",
      py::arg("base") = "", py::arg("stamp_at") = "auto", py::arg("models") = "", py::arg("start") = 0.0, py::arg("duration") = 0.0,
      py::arg("overwrite") = false, py::arg("progress") = py::none(), py::arg("arguments") = std::vector<std::string>{});
  module.def(
      "slam",
      [](const std::filesystem::path& out, const std::filesystem::path& dataset, const std::string& bag,
         const std::filesystem::path& config, const std::string& calibrate, int threads, double max_base_gaps,
         const std::string& extrinsics, const std::string& topics, const std::string& base, const std::string& stamp_at,
         const std::string& models, double start, double duration, bool overwrite, const py::object& progress,
         const std::vector<std::string>& arguments) {
        io::BagArguments bag_options = bag_arguments(bag, topics, stamp_at, extrinsics, models, start, duration);
        bag_options.base = base;
        return run_slam({out, overwrite, arguments}, dataset, bag_options, config, calibrate, threads, max_base_gaps, progress);
      },
      py::kw_only(), py::arg("out"), py::arg("dataset") = "", py::arg("bag") = "", py::arg("config") = "", py::arg("calibrate") = "online",
      py::arg("threads") = 0, py::arg("max_base_gaps") = pipelines::kDefaultMaxBaseGaps, py::arg("extrinsics") = "", py::arg("topics") = "",
      py::arg("base") = "", py::arg("stamp_at") = "auto", py::arg("models") = "", py::arg("start") = 0.0, py::arg("duration") = 0.0,
      py::arg("overwrite") = false, py::arg("progress") = py::none(), py::arg("arguments") = std::vector<std::string>{});
  module.def(
      "calibrate_auto",
      [](const std::filesystem::path& out, const std::filesystem::path& dataset, const std::string& bag, const std::string& base,
         const std::string& stage, const std::filesystem::path& init, const std::filesystem::path& config, std::optional<int> pair_stride,
         int threads, double max_base_gaps, const std::string& extrinsics, const std::string& topics, const std::string& stamp_at,
         const std::string& models, double start, double duration, bool overwrite, const py::object& progress,
         const std::vector<std::string>& arguments) {
        return run_calibrate_auto({out, overwrite, arguments}, dataset,
                                  bag_arguments(bag, topics, stamp_at, extrinsics, models, start, duration), base, stage, init, config,
                                  pair_stride, threads, max_base_gaps, progress);
      },
      py::kw_only(), py::arg("out"), py::arg("dataset") = "", py::arg("bag") = "", py::arg("base") = "", py::arg("stage") = "all",
      py::arg("init") = "", py::arg("config") = "", py::arg("pair_stride") = py::none(), py::arg("threads") = 0,
      py::arg("max_base_gaps") = pipelines::kDefaultMaxBaseGaps, py::arg("extrinsics") = "", py::arg("topics") = "",
      py::arg("stamp_at") = "auto", py::arg("models") = "", py::arg("start") = 0.0, py::arg("duration") = 0.0, py::arg("overwrite") = false,
      py::arg("progress") = py::none(), py::arg("arguments") = std::vector<std::string>{});
}

}  // namespace mlidar::python
