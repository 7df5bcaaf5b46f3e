// Detection hot paths without a network (issue 23's 200 ms per frame for 3 LiDARs on 2 threads leaves these a few
// ms): a lyft-sized frame's 200 000 points into the stage-1 BEV grid (96 m x 96 m, 0.4 m pillars), 30 cars'
// anchor targets on its head grid (stride 2, two yaws: 28 800 anchors), result fusion of 3 LiDARs x 100 boxes, and
// online calibration of a simulated lyft street frame (both side LiDARs registered to the top one, alpha 0.04), and
// the whole frame read with it (`detect run --refine-extrinsics`) on 1 or 2 threads.
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <unistd.h>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "mlidar/core/extrinsic_perturbation.hpp"
#include "mlidar/detect/anchor_targets.hpp"
#include "mlidar/detect/bev_grid.hpp"
#include "mlidar/detect/detection_frames.hpp"
#include "mlidar/detect/online_extrinsics.hpp"
#include "mlidar/detect/result_fusion.hpp"
#include "mlidar/eval/calibration_metrics.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/sim/detection_dataset.hpp"
#include "mlidar/sim/rig.hpp"

namespace {

using namespace mlidar;

std::vector<io::Box3D> random_cars(std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> position(-45.0, 45.0), yaw(-std::numbers::pi, std::numbers::pi), size(0.9, 1.1);
  std::vector<io::Box3D> cars;
  for (std::size_t k = 0; k < count; ++k) cars.push_back({Vec3(position(rng), position(rng), 0.0), 4.2 * size(rng), 1.8 * size(rng), 1.6, yaw(rng)});
  return cars;
}

void BM_BevGrid200k(benchmark::State& state) {
  std::mt19937 rng(1);
  std::normal_distribution<double> spread(0.0, 20.0), height(0.0, 1.0);
  std::vector<Vec3> points;
  std::vector<float> intensity;
  std::vector<double> uncertainty;
  for (int k = 0; k < 200000; ++k) {
    points.emplace_back(spread(rng), spread(rng), height(rng));
    intensity.push_back(static_cast<float>(k % 255));
    uncertainty.push_back(0.001);
  }
  for (auto _ : state) benchmark::DoNotOptimize(detect::make_bev_grid(points, intensity, uncertainty, detect::BevGridConfig{}));
}
BENCHMARK(BM_BevGrid200k)->Unit(benchmark::kMillisecond);

void BM_AnchorTargets30Cars(benchmark::State& state) {
  const std::vector<io::Box3D> cars = random_cars(30, 2);
  for (auto _ : state) benchmark::DoNotOptimize(detect::assign_anchors(cars, detect::BevGridConfig{}, detect::AnchorConfig{}));
}
BENCHMARK(BM_AnchorTargets30Cars)->Unit(benchmark::kMillisecond);

void BM_ResultFusion3x100(benchmark::State& state) {
  std::vector<detect::LidarDetections> lidars(3);
  for (std::size_t l = 0; l < 3; ++l)
    for (const io::Box3D& box : random_cars(100, static_cast<unsigned>(l + 3)))
      lidars[l].boxes.push_back({io::ObjectClass::kCar, box, 0.5, 0});
  for (auto _ : state) benchmark::DoNotOptimize(detect::fuse_results(lidars, 0.1));
}
BENCHMARK(BM_ResultFusion3x100)->Unit(benchmark::kMillisecond);

/// Writes a one-frame simulated lyft test dataset to a new temporary folder named after `tag`; returns the folder.
std::filesystem::path write_lyft_test_frame(const std::string& tag) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / ("mlidar_bench_" + tag + "_" + std::to_string(::getpid()));
  sim::DetectionSpec spec;
  spec.rig = sim::load_rig("lyft");
  spec.frames = 1;
  spec.split = sim::DetectionSplit::kTest;
  sim::write_detection_dataset(spec, folder);
  return folder;
}

/// Arg 0: online_refine_config(); 1: `calibrate refine`'s defaults without the search. Counters: trusted share and
/// mean rotation error (deg) against the simulator's extrinsics.
void BM_OnlineCalibrationLyftFrame(benchmark::State& state) {
  const std::filesystem::path folder = write_lyft_test_frame("oc");
  const io::FrameSource source = io::FrameSource::dataset(folder);
  const io::SourceFrame frame = source.read(0);
  std::filesystem::remove_all(folder);
  const std::size_t ref = source.reference_index().value_or(0);
  calib::PairRefineConfig config = detect::online_refine_config();
  if (state.range(0) == 1) {
    config = calib::PairRefineConfig{};
    config.search_mode = calib::PairSearchMode::kNever;
  }
  std::mt19937_64 rng(4);
  double trusted = 0.0, error_deg = 0.0, registrations = 0.0;
  for (auto _ : state) {
    for (std::size_t j = 0; j < source.lidars().size(); ++j) {
      if (j == ref) continue;
      const SE3 truth = *source.lidars()[j].initial_extrinsic;
      PerturbationPrior prior;
      prior.alpha = 0.04;
      const detect::RefinedExtrinsic refined = detect::refine_extrinsic_online(
          *frame.scans[ref], *source.lidars()[ref].initial_extrinsic, *frame.scans[j], sample_perturbed_extrinsic(truth, prior, rng), config);
      trusted += refined.trusted() ? 1.0 : 0.0;
      error_deg += eval::extrinsic_error(truth, refined.uncertain_extrinsic.T, std::nullopt).rotation_error_deg;
      registrations += 1.0;
    }
  }
  state.counters["trusted"] = trusted / registrations;
  state.counters["rot_err_deg"] = error_deg / registrations;
}
BENCHMARK(BM_OnlineCalibrationLyftFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// A lyft test frame read with online calibration (its two side LiDARs registered in parallel), alpha 0.04;
/// arg: TBB threads (1: the registrations one after the other).
void BM_ReadFrameWithOnlineCalibration(benchmark::State& state) {
  const std::filesystem::path folder = write_lyft_test_frame("read_oc");
  const detect::DetectionDataset dataset = detect::DetectionDataset::open(folder, false);
  const calib::PairRefineConfig online = detect::online_refine_config();
  const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(dataset.read(0, 0.04, 4, &online));
  std::filesystem::remove_all(folder);
}
BENCHMARK(BM_ReadFrameWithOnlineCalibration)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
