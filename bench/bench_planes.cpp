// PS-Calib time for the thesis's 9500-point corner problem (Sec. 2.4.2):
// plane extraction, corner, closed form and refinement, one thread.
#include <filesystem>

#include <benchmark/benchmark.h>

#include "mlidar/calib/planes_calibrator.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/sim/corner_dataset.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<Eigen::Vector3f> read_points(const fs::path& file) {
  return mlidar::io::to_scan(mlidar::io::read_cloud(file).table, file.string()).points;
}

void BM_PlanesCalibration9500(benchmark::State& state) {
  const fs::path dir = fs::temp_directory_path() / "mlidar_bench_planes";
  fs::remove_all(dir);
  mlidar::sim::CornerSpec spec;
  spec.configuration = static_cast<int>(state.range(0));
  spec.angle_min = spec.angle_max = 90.0;
  mlidar::sim::write_corner_dataset(spec, dir);
  const auto ref = read_points(dir / "scans" / "l1" / "000000.pcd");
  const auto target = read_points(dir / "scans" / "l2" / "000000.pcd");
  fs::remove_all(dir);
  const mlidar::calib::PlanesCalibrator calibrator{mlidar::calib::PlanesConfig{}};
  for (auto _ : state) {
    benchmark::DoNotOptimize(calibrator.calibrate(ref, target, std::nullopt, "l1", "l2"));
  }
}
BENCHMARK(BM_PlanesCalibration9500)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);

}  // namespace
