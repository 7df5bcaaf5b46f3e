// Simulator throughput: frames per second (all LiDARs of the rig) on one core.
// Targets: >= 20 frames/s for rv/campus (four RS-LiDAR-16), >= 10 frames/s
// for single-hdl64/street (HDL-64E, 64 x 2083 beams).
#include <benchmark/benchmark.h>

#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/scenes.hpp"

namespace {

using namespace mlidar;
using namespace mlidar::sim;

void simulate_frames(benchmark::State& state, const char* rig_name, const char* scene_name) {
  const SimRig rig = named_rig(rig_name);
  const SimTrajectory trajectory = SimTrajectory::named("vehicle", rig.base_height);
  constexpr int kFrames = 100;
  std::vector<Vec3> path;
  for (int k = 0; k <= kFrames; ++k) path.push_back(trajectory.T_world_base(k * rig.frame_period()).translation());
  const Scene scene = make_scene(scene_name, 1, path);
  std::size_t frame = 0;
  std::size_t points = 0;
  for (auto _ : state) {
    const double stamp = static_cast<double>(frame % kFrames) * rig.frame_period();
    for (std::size_t i = 0; i < rig.lidars.size(); ++i) {
      const auto sweep = simulate_sweep(scene, rig.lidars[i], trajectory, stamp, sweep_seed(1, frame, i));
      points += sweep.scan.size();
      benchmark::DoNotOptimize(sweep.scan.points.data());
    }
    ++frame;
  }
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(frame), benchmark::Counter::kIsRate);
  state.counters["points/frame"] = static_cast<double>(points) / static_cast<double>(frame);
}

void BM_RvCampus(benchmark::State& state) { simulate_frames(state, "rv", "campus"); }
void BM_Hdl64Street(benchmark::State& state) { simulate_frames(state, "single-hdl64", "street"); }

BENCHMARK(BM_RvCampus)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_Hdl64Street)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
