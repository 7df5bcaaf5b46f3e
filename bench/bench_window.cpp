// Back end (issue 9): one sliding-window solve at the thesis's size (N = 4,
// p = 2: 5 poses, the first 2 fixed; 2 LiDARs, the auxiliary extrinsic a
// variable), 1500 features per LiDAR per frame (15000 correspondences, 3 in 4
// on planes), features with 2 cm noise, the variables perturbed by 5 cm / 2 deg.
// Single thread (tbb::global_control; the library leaves threads to the caller).
#include <algorithm>
#include <random>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#if MLIDAR_WITH_CERES
#include "mlidar/slam/ceres_window.hpp"
#endif
#include "mlidar/slam/marginalization.hpp"
#include "mlidar/slam/window_solver.hpp"
#include "slam/window_scene.hpp"

namespace {

using namespace mlidar;
using namespace mlidar::slam;

struct Window {
  WindowProblem problem;
  WindowState initial;
};

/// `fixed_poses`: 2 (the thesis's pivot window) or 5 (the online calibration
/// window: every pose fixed by the map, the extrinsic alone variable).
Window make_window(int fixed_poses = 2) {
  std::mt19937_64 rng(7);
  const test::WindowScene scene = test::room_scene(20, rng);
  std::vector<SE3> poses;
  for (int k = 0; k < 5; ++k) poses.emplace_back(so3_exp(Vec3(0.0, 0.01 * k, 0.1 * k)), Vec3(0.5 * k, 0.05 * k, 0.0));
  const std::vector<SE3> extrinsics{SE3(), SE3(so3_exp(Vec3(0.2, -0.1, 1.6)), Vec3(0.4, -0.3, 0.1))};
  Window window;
  window.initial = WindowState::make(poses, extrinsics, fixed_poses, true);
  window.problem = test::observe(scene, window.initial, 1500, rng);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (auto& c : window.problem.planes) c.point_lidar += Vec3(noise(rng), noise(rng), noise(rng));
  for (auto& c : window.problem.edges) c.point_lidar += Vec3(noise(rng), noise(rng), noise(rng));
  for (std::size_t i = static_cast<std::size_t>(fixed_poses); i < poses.size(); ++i)
    window.initial.T_world_base[i] = test::perturb(poses[i], 0.05, 0.035, rng);
  window.initial.T_base_lidar[1] = test::perturb(extrinsics[1], 0.05, 0.035, rng);
  return window;
}

void BM_WindowSolve(benchmark::State& bench) {
  const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
  const Window window = make_window();
  WindowSolution solution;
  for (auto _ : bench) {
    solution = solve_window(window.problem, window.initial);
    benchmark::DoNotOptimize(solution.final_cost);
  }
  bench.counters["correspondences"] = static_cast<double>(window.problem.planes.size() + window.problem.edges.size());
  bench.counters["iterations"] = solution.iterations;
  bench.counters["converged"] = solution.converged ? 1.0 : 0.0;
}
BENCHMARK(BM_WindowSolve)->Unit(benchmark::kMillisecond);

/// The solver comparison (issue 9 Method): the same window by the hand-written LM
/// and by Ceres (ProductManifold SO(3) x R^3, autodiff; arg 1: DENSE_QR, else
/// DENSE_NORMAL_CHOLESKY), 30 iterations allowed each; counters: the final cost
/// and the largest pose / extrinsic difference from the hand-written solution.
void solver_counters(benchmark::State& bench, const Window& window, const WindowState& state, double final_cost, int iterations) {
  const WindowSolution reference = solve_window(window.problem, window.initial, {.max_iterations = 30});
  double largest = 0.0;
  for (std::size_t i = 0; i < state.T_world_base.size(); ++i)
    largest = std::max(largest, (state.T_world_base[i].inverse() * reference.state.T_world_base[i]).log().norm());
  largest = std::max(largest, (state.T_base_lidar[1].inverse() * reference.state.T_base_lidar[1]).log().norm());
  bench.counters["final_cost"] = final_cost;
  bench.counters["iterations"] = iterations;
  bench.counters["diff_from_ours"] = largest;
}

void BM_SolverOurs(benchmark::State& bench) {
  const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
  const Window window = make_window(static_cast<int>(bench.range(0)));
  WindowSolution solution;
  for (auto _ : bench) {
    solution = solve_window(window.problem, window.initial, {.max_iterations = 30});
    benchmark::DoNotOptimize(solution.final_cost);
  }
  solver_counters(bench, window, solution.state, solution.final_cost, solution.iterations);
}
BENCHMARK(BM_SolverOurs)->Arg(2)->Arg(5)->Unit(benchmark::kMillisecond);

#if MLIDAR_WITH_CERES
void BM_SolverCeres(benchmark::State& bench) {
  const Window window = make_window(static_cast<int>(bench.range(0)));
  CeresWindowResult result;
  for (auto _ : bench) {
    result = solve_window_ceres(window.problem, window.initial, {.max_iterations = 30, .dense_qr = bench.range(1) == 1});
    benchmark::DoNotOptimize(result.final_cost);
  }
  solver_counters(bench, window, result.state, result.final_cost, result.iterations);
}
BENCHMARK(BM_SolverCeres)->Args({2, 0})->Args({2, 1})->Args({5, 0})->Unit(benchmark::kMillisecond);
#endif

void BM_WindowLinearize(benchmark::State& bench) {
  const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
  const Window window = make_window();
  const VariableLayout layout(window.initial);
  for (auto _ : bench) benchmark::DoNotOptimize(linearize_window(window.problem, window.initial, layout, 0.1).cost);
}
BENCHMARK(BM_WindowLinearize)->Unit(benchmark::kMillisecond);

void BM_MarginalizeOldest(benchmark::State& bench) {
  const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
  Window window = make_window();
  window.initial.pose_fixed.assign(5, false);  // a variable oldest pose: the Schur complement does work
  for (auto _ : bench) benchmark::DoNotOptimize(marginalize_frame(window.problem, window.initial, 0, 0.1).residual.data());
}
BENCHMARK(BM_MarginalizeOldest)->Unit(benchmark::kMillisecond);

}  // namespace
