// `calibrate refine` on one real OpenCalib pair (opencalib_3lidar scene 0002,
// top <- left, 90k + 9k points), one thread. From initial_extrinsic.txt the
// guess is ~45 deg off in pitch, so the ground-plane yaw search runs: this is
// the whole job a user waits for. Arg 1: the same with --search never from
// the refined answer (ICP alone).
#include <filesystem>

#include <benchmark/benchmark.h>

#include "mlidar/calib/pair_refine.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/opencalib.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<Eigen::Vector3f> read_points(const fs::path& file) {
  return mlidar::io::to_scan(mlidar::io::read_cloud(file).table, file.string()).points;
}

void BM_PairRefineOpenCalib(benchmark::State& state) {
  const fs::path scene = fs::path(MLIDAR_SHARED_DATA) / "real" / "opencalib_3lidar" / "0002";
  if (!fs::exists(scene)) {
    state.SkipWithError("shared data not found");
    return;
  }
  const auto ref = read_points(scene / "top-2022-02-15-17-36-04-449.pcd");
  const auto target = read_points(scene / "left-2022-02-15-17-36-04-414.pcd");
  const mlidar::io::Extrinsics initial = mlidar::io::read_opencalib_initial_extrinsics(scene / "initial_extrinsic.txt");
  if (initial.find("device_1") == nullptr) {
    state.SkipWithError("initial_extrinsic.txt has no device_1");
    return;
  }
  mlidar::SE3 T_init = initial.find("device_1")->T_base_lidar;
  mlidar::calib::PairRefineConfig config;
  if (state.range(0) == 1) {
    T_init = mlidar::calib::refine_pair(ref, target, T_init, config).T_ref_target;
    config.search_mode = mlidar::calib::PairSearchMode::kNever;
  }
  for (auto _ : state) {
    const auto result = mlidar::calib::refine_pair(ref, target, T_init, config);
    benchmark::DoNotOptimize(result);
    if (result.verdict == mlidar::calib::PairVerdict::kNotConverged) state.SkipWithError("did not converge");
  }
}
BENCHMARK(BM_PairRefineOpenCalib)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace
