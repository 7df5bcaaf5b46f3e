// Evaluation hot paths: ATE + RPE + KITTI metric on 100 000 poses (target < 0.2 s),
// mean map entropy on 1 M points (synthetic room: floor, walls, noise 1 cm), and
// detection AP on 10 000 objects and 10 000 predictions (issue 22: <= 1 s).
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "mlidar/eval/detection_ap.hpp"
#include "mlidar/eval/map_metrics.hpp"
#include "mlidar/eval/trajectory_metrics.hpp"

namespace {

using namespace mlidar;

Trajectory noisy_copy(const Trajectory& gt, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.02);
  Trajectory est = gt;
  for (StampedPose& pose : est.poses) {
    pose.stamp += 0.001 * noise(rng);
    pose.T_world_base =
        pose.T_world_base * SE3(so3_exp(Vec3(noise(rng), noise(rng), noise(rng)) * 0.05), Vec3(noise(rng), noise(rng), noise(rng)));
  }
  return est;
}

Trajectory long_drive(std::size_t count) {
  Trajectory trajectory;
  for (std::size_t i = 0; i < count; ++i) {
    const double s = 0.001 * static_cast<double>(i);
    trajectory.poses.push_back(
        {0.1 * static_cast<double>(i), SE3(so3_exp(Vec3(0.0, 0.0, 3.0 * s)), Vec3(300.0 * std::cos(s), 200.0 * std::sin(2.0 * s), 0.0))});
  }
  return trajectory;
}

void BM_TrajectoryEval100k(benchmark::State& state) {
  const Trajectory gt = long_drive(100000);
  const Trajectory est = noisy_copy(gt, 1);
  eval::TrajectoryEvalOptions options;
  options.align = eval::AlignMode::kSim3;
  for (auto _ : state) {
    const eval::TrajectoryReport report = eval::evaluate_trajectory(gt, est, options, "gt", "est");
    benchmark::DoNotOptimize(report.ate.translation_m.rmse);
  }
  state.SetItemsProcessed(state.iterations() * 100000);
}
BENCHMARK(BM_TrajectoryEval100k)->Unit(benchmark::kMillisecond);

/// Points on the floor and four walls of a 30 x 30 x 5 m room, 1 cm Gaussian noise.
std::vector<Eigen::Vector3f> room_cloud(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  std::normal_distribution<float> noise(0.0F, 0.01F);
  std::vector<Eigen::Vector3f> points(count);
  for (auto& p : points) {
    const float a = 30.0F * u(rng);
    const float b = u(rng);
    switch (static_cast<int>(5.0F * u(rng))) {
      case 0:
        p = {a, 30.0F * b, noise(rng)};
        break;
      case 1:
        p = {a, noise(rng), 5.0F * b};
        break;
      case 2:
        p = {a, 30.0F + noise(rng), 5.0F * b};
        break;
      case 3:
        p = {noise(rng), a, 5.0F * b};
        break;
      default:
        p = {30.0F + noise(rng), a, 5.0F * b};
        break;
    }
  }
  return points;
}

void BM_MeanMapEntropy(benchmark::State& state) {
  const auto cloud = room_cloud(static_cast<std::size_t>(state.range(0)), 2);
  for (auto _ : state) {
    const eval::MapMetrics metrics = eval::compute_map_metrics(cloud, {.radius = 0.3, .min_neighbors = 5});
    benchmark::DoNotOptimize(metrics.mean_map_entropy);
    state.counters["mme"] = metrics.mean_map_entropy;
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_MeanMapEntropy)->Arg(100000)->Arg(1000000)->Iterations(1)->Unit(benchmark::kMillisecond);

/// `frames` frames of `per_frame` objects each (classes in turn, up to 60 m around the vehicle) and as many
/// predictions: 80 % noisy copies (5 cm, 2°), 20 % false positives, scores uniform.
std::vector<eval::DetectionFrame> street_frames(int frames, int per_frame) {
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> place(-60.0, 60.0), unit(0.0, 1.0), yaw(-3.14159, 3.14159);
  std::normal_distribution<double> noise(0.0, 0.05);
  const double sizes[3][3] = {{4.5, 1.8, 1.6}, {0.6, 0.6, 1.8}, {1.8, 0.6, 1.7}};
  std::vector<eval::DetectionFrame> out(static_cast<std::size_t>(frames));
  for (eval::DetectionFrame& frame : out) {
    for (int k = 0; k < per_frame; ++k) {
      const auto object_class = io::kObjectClasses[static_cast<std::size_t>(k % 3)];
      const double* lwh = sizes[k % 3];
      const io::LabelledBox truth{object_class, {{place(rng), place(rng), -1.7}, lwh[0], lwh[1], lwh[2], yaw(rng)}, std::nullopt, 0};
      frame.ground_truth.push_back(truth);
      io::LabelledBox prediction = truth;
      if (unit(rng) < 0.8) {
        prediction.box.center_bottom += Vec3(noise(rng), noise(rng), noise(rng));
        prediction.box.yaw += 0.7 * noise(rng);
      } else {
        prediction.box.center_bottom = {place(rng), place(rng), -1.7};
      }
      prediction.score = unit(rng);
      frame.predictions.push_back(prediction);
    }
  }
  return out;
}

void BM_DetectionEval10k(benchmark::State& state) {
  const std::vector<eval::DetectionFrame> frames =
      street_frames(static_cast<int>(10000 / state.range(0)), static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(eval::evaluate_detections(frames, eval::DetectionEvalConfig{}));
}
// 10 objects a frame (1000 frames, a KITTI-like density) and 100 (100 frames, a crowded street).
BENCHMARK(BM_DetectionEval10k)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond);

}  // namespace
