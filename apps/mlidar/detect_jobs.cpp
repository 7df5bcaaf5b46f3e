// mlidar-detect's jobs (detect_command.hpp): `detect train` and `detect run` on MLOD's networks (LibTorch).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "apps/mlidar/detect_command.hpp"
#include "apps/mlidar/progress_bar.hpp"
#include "mlidar/detect/detect_config.hpp"
#include "mlidar/detect/model_folder.hpp"
#include "mlidar/detect/net/detector.hpp"
#include "mlidar/detect/online_calibration_log.hpp"
#include "mlidar/detect/online_extrinsics.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/detection_labels.hpp"
#include "mlidar/io/run_folder.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"

namespace mlidar::cli {
namespace {

namespace fs = std::filesystem;

/// metrics.json's "online_calibration": per LiDAR what the registrations did (summaries as {mean, p50, p95, max}).
nlohmann::json online_calibration_json(const detect::OnlineCalibrationLog& log) {
  nlohmann::json lidars = nlohmann::json::array();
  for (const detect::LidarRefineRecord& record : log.records()) {
    if (record.registrations == 0) continue;
    nlohmann::json lidar = {{"lidar", record.lidar},
                            {"registrations", record.registrations},
                            {"trusted", record.trusted},
                            {"rotation_change_deg", pipelines::timing_summary(record.rotation_change_deg)},
                            {"translation_change_m", pipelines::timing_summary(record.translation_change_m)}};
    if (log.knows_truth()) {
      lidar["rotation_error_deg"] = {{"given", pipelines::timing_summary(record.rotation_error_given_deg)},
                                     {"used", pipelines::timing_summary(record.rotation_error_used_deg)}};
      lidar["translation_error_m"] = {{"given", pipelines::timing_summary(record.translation_error_given_m)},
                                      {"used", pipelines::timing_summary(record.translation_error_used_m)}};
    }
    lidars.push_back(lidar);
  }
  return {{"registrations", log.registrations()}, {"untrusted", log.untrusted()}, {"lidars", lidars}};
}

std::string clock_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char text[32];
  if (s >= 3600) std::snprintf(text, sizeof(text), "%ldh%02ldm", s / 3600, (s / 60) % 60);
  else std::snprintf(text, sizeof(text), "%ldm%02lds", s / 60, s % 60);
  return text;
}

/// "stage 1 [#####     ] 120/2000 loss 0.8123 ETA 12m03s" on stderr when it is a terminal.
std::function<void(const detect::TrainProgress&)> training_progress_bar() {
  if (isatty(fileno(stderr)) == 0) return {};
  return [](const detect::TrainProgress& p) {
    constexpr long kWidth = 30;
    const long filled = p.steps > 0 ? kWidth * p.step / p.steps : kWidth;
    const long run = p.step - p.first_step;
    const double eta = run > 0 ? p.seconds / static_cast<double>(run) * static_cast<double>(p.steps - p.step) : 0.0;
    std::fprintf(stderr, "\rstage %d [%s%s] %ld/%ld loss %.4f ETA %s   ", p.stage, std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), ' ').c_str(), p.step, p.steps, p.loss, clock_text(eta).c_str());
    if (p.step == p.steps) std::fputc('\n', stderr);
  };
}

int run_train(const DetectTrainOptions& options) {
  detect::TrainRequest request;
  request.data = options.data;
  request.out = options.out;
  request.fusion = detect::fusion_from_name(options.fusion, "--fusion");
  request.lidar = options.lidar;
  request.stage = options.stage;
  request.resume = options.resume;
  request.max_steps = options.max_steps;
  // --resume without --config goes on with the folder's own configuration.
  if (!options.config.empty()) {
    request.config = detect::read_detect_config(options.config);
  } else if (options.resume || options.stage == 2) {
    request.config = detect::read_model_detect_config(fs::path(options.out) / "detect.yaml");
  }
  if (options.threads > 0) request.config.threads = options.threads;
  detect::train_detector(request, training_progress_bar());
  const detect::ModelFolder model = detect::read_model_folder(options.out);
  std::cout << "wrote " << options.out << ": " << detect::fusion_name(model.info.fusion) << " fusion"
            << (model.info.lidar.empty() ? "" : " (" + model.info.lidar + ")") << ", stages";
  for (const int stage : model.info.stages) std::cout << ' ' << stage;
  std::cout << '\n';
  for (const auto& [stage, record] : model.info.records) {
    std::cout << "  stage " << stage << ": " << record.steps << " steps, final loss " << record.final_loss << ", " << record.seconds << " s\n";
  }
  return 0;
}

int run_detect(const DetectRunOptions& options, const CliContext& context) {
  const detect::Detector detector = detect::Detector::load(options.model, options.stage, options.threads);
  const detect::DetectionDataset dataset = detect::DetectionDataset::open(options.dataset, /*need_labels=*/false);
  const std::vector<std::size_t> indices =
      detect::model_lidar_indices(detector.info(), dataset.lidar_names(), (fs::path(options.dataset) / "dataset.yaml").string());
  io::RunFolder run(options.out, "detect run", context.run_folder(options.overwrite, {options.dataset, options.model}));
  fs::create_directories(run.path() / "label_2");
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point from) { return std::chrono::duration<double, std::milli>(Clock::now() - from).count(); };
  nlohmann::json per_frame = nlohmann::json::array();
  std::vector<double> read_ms, stage1_ms, stage2_ms, total_ms;
  std::size_t detections = 0;
  // The truth is known where the perturbations are drawn here, about the dataset's own extrinsics.
  detect::OnlineCalibrationLog online_log(dataset.lidar_names(), options.alpha > 0.0 ? dataset.dataset_extrinsics() : std::vector<SE3>{});
  const calib::PairRefineConfig online = detect::online_refine_config();
  const auto progress = terminal_progress_bar();
  for (std::size_t k = 0; k < dataset.frames(); ++k) {
    const Clock::time_point start = Clock::now();
    detect::DetectionFrame all = dataset.read(k, options.alpha, options.seed, options.refine_extrinsics ? &online : nullptr);
    online_log.add(all);
    const detect::DetectionFrame frame = detect::select_lidars(std::move(all), indices);
    const double read = ms(start);
    const detect::FrameDetections result = detector.detect(frame);
    io::write_detection_labels(run.path() / "label_2" / (frame.id + ".txt"), result.boxes);
    detections += result.boxes.size();
    read_ms.push_back(read), stage1_ms.push_back(result.stage1_ms), stage2_ms.push_back(result.stage2_ms);
    total_ms.push_back(result.stage1_ms + result.stage2_ms);
    per_frame.push_back({{"frame", frame.id}, {"detections", result.boxes.size()}, {"read_ms", read}, {"stage1_ms", result.stage1_ms},
                         {"stage2_ms", result.stage2_ms}, {"detect_ms", result.stage1_ms + result.stage2_ms}});
    if (progress) progress(static_cast<int>(k) + 1, static_cast<int>(dataset.frames()));
  }
  std::vector<int> stages = {1};
  if (detector.refines()) stages.push_back(2);
  const nlohmann::json metrics = {{"model", fs::absolute(options.model).string()},
                                  {"fusion", detect::fusion_name(detector.info().fusion)},
                                  {"lidars", detector.info().lidars},
                                  {"class", io::object_class_name(detector.config().object_class)},
                                  {"stages_run", stages},
                                  {"alpha", options.alpha},
                                  {"seed", options.seed},
                                  {"refine_extrinsics", options.refine_extrinsics},
                                  {"online_calibration", options.refine_extrinsics ? online_calibration_json(online_log) : nlohmann::json(nullptr)},
                                  {"threads", options.threads > 0 ? options.threads : detector.config().threads},
                                  {"frames", dataset.frames()},
                                  {"detections", detections},
                                  {"detect_ms", pipelines::timing_summary(total_ms)},
                                  {"stage1_ms", pipelines::timing_summary(stage1_ms)},
                                  {"stage2_ms", pipelines::timing_summary(stage2_ms)},
                                  {"read_ms", pipelines::timing_summary(read_ms)},
                                  {"per_frame", per_frame}};
  io::write_atomically(run.path() / "metrics.json", [&](std::ostream& out) { out << metrics.dump(2) << '\n'; });
  run.commit();
  std::cout << "wrote " << options.out << ": " << detections << " detections in " << dataset.frames() << " frames, "
            << metrics["detect_ms"]["mean"].get<double>() << " ms per frame (mean, stages";
  for (const int stage : stages) std::cout << ' ' << stage;
  std::cout << ")\n";
  if (online_log.untrusted() > 0) {
    std::cerr << "warning: online calibration did not trust " << online_log.untrusted() << " of " << online_log.registrations()
              << " registrations; those LiDARs kept the given extrinsic in those frames (metrics.json: online_calibration)\n";
  }
  return 0;
}

}  // namespace

DetectJobs detect_network_jobs(const CliContext& context) {
  return {run_train, [&context](const DetectRunOptions& options) { return run_detect(options, context); }};
}

}  // namespace mlidar::cli
