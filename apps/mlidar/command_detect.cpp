// `mlidar detect train|run`'s options (detect_command.hpp): the same in mlidar, which checks them and hands the
// command line to mlidar-detect, and in mlidar-detect, which runs the job.
#include <memory>
#include <string>
#include <utility>

#include "apps/mlidar/detect_command.hpp"

namespace mlidar::cli {
namespace {

void add_train(CLI::App& detect, DetectTrainOptions& options) {
  CLI::App* sub = detect.add_subcommand("train", "Train MLOD (thesis 6.5): stage 1 (BEV network), then stage 2 (PointNet refinement)");
  sub->add_option("--data", options.data, "Labelled dataset (`mlidar simulate detection`), frames in groundtruth/label_2")->required();
  sub->add_option("--config", options.config, "detect.yaml (config/detect.yaml documents every key; default: the defaults, "
                                               "or the model folder's own with --resume)");
  sub->add_option("--fusion", options.fusion, "none (one LiDAR, --lidar), input, feature or result (thesis 6.5.1)")
      ->check(CLI::IsMember({"none", "input", "feature", "result"}))
      ->capture_default_str();
  sub->add_option("--lidar", options.lidar, "With --fusion none: the LiDAR the detector reads");
  sub->add_option("--stage", options.stage, "Train stage 1 or 2 only (2: on a model folder with a trained stage 1); default both")
      ->check(CLI::Range(1, 2));
  sub->add_option("--out", options.out, "The model folder (new or empty; an unfinished training with --resume)")->required();
  sub->add_flag("--resume", options.resume, "Continue the training in --out from its last checkpoint");
  sub->add_option("--max-steps", options.max_steps, "Stop each stage after this many steps (quick looks, tests)")->check(CLI::Range(1L, 1000000000L));
  sub->add_option("--threads", options.threads, "LibTorch threads (default: the configuration's `threads`)")->check(CLI::Range(1, 256));
}

void add_run(CLI::App& detect, DetectRunOptions& options) {
  CLI::App* sub = detect.add_subcommand("run", "Detect objects in a dataset with a trained model: label_2 files with scores");
  sub->add_option("--model", options.model, "Model folder written by `mlidar detect train`")->required();
  sub->add_option("--dataset", options.dataset, "Dataset folder (labels not needed)")->required();
  sub->add_option("--alpha", options.alpha, "Perturb every frame's extrinsics anew at this level (thesis 6.6.1.3, 0 to 0.1)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--seed", options.seed, "Seed of the --alpha perturbations (one per trial)")->capture_default_str();
  sub->add_flag("--refine-extrinsics", options.refine_extrinsics,
                "Online calibration first (the thesis's (OC)): each frame's extrinsics registered to the reference LiDAR's "
                "scan by `calibrate refine`'s ICP; metrics.json's online_calibration says what it did");
  sub->add_option("--stage", options.stage, "1: stage 1 alone (of a two-stage model); 2: require stage 2; default all trained stages")
      ->check(CLI::Range(1, 2));
  sub->add_option("--threads", options.threads, "LibTorch threads (default: the model's configuration)")->check(CLI::Range(1, 256));
  sub->add_option("--out", options.out, "Predictions: label_2/NNNNNN.txt with scores, metrics.json (timing)")->required();
  add_overwrite_flag(*sub, options.overwrite);
}

}  // namespace

Command register_detect(CLI::App& app, DetectJobs jobs) {
  auto train = std::make_shared<DetectTrainOptions>();
  auto run = std::make_shared<DetectRunOptions>();
  CLI::App* sub = app.add_subcommand("detect", "3D object detection from several LiDARs (MLOD, thesis Ch. 6; needs LibTorch)");
  sub->require_subcommand(1);
  add_train(*sub, *train);
  add_run(*sub, *run);
  CLI::App* train_cmd = sub->get_subcommand("train");
  return {sub, [train, run, train_cmd, jobs = std::move(jobs)] { return train_cmd->parsed() ? jobs.train(*train) : jobs.run(*run); }};
}

}  // namespace mlidar::cli
