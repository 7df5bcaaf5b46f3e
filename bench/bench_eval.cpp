// Evaluation hot paths: ATE + RPE + KITTI metric on 100 000 poses (target < 0.2 s)
// and mean map entropy on 1 M points (synthetic room: floor, walls, noise 1 cm).
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

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

}  // namespace
