// Thesis Table 2.3 protocol (Sec. 2.4.2) for PS-Calib: for each Table 2.2
// configuration and alpha in 60..120 deg, `trials` seeded corner datasets from
// the simulator (`mlidar simulate corner`: 9500 points, 7500 on the planes with
// sigma 0.1 m, 2000 outliers sigma 5 m), calibrated with the default config.
// Prints a markdown table: mean/std of the rotation error |Log(R_gt R^-1)|
// (rad) and translation error (m), failures (an exception, or errors above the
// thesis's own 0.05 rad / 0.1 m), median time per calibration.
// Usage: planes_table [trials=10] [scratch folder=/tmp/mlidar_planes_table]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "mlidar/calib/planes_calibrator.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/sim/corner_dataset.hpp"

namespace {

namespace fs = std::filesystem;
using mlidar::SE3;

struct Cell {
  std::vector<double> rotation, translation, seconds;
  int failures = 0;
};

std::vector<Eigen::Vector3f> read_points(const fs::path& file) {
  return mlidar::io::to_scan(mlidar::io::read_cloud(file).table, file.string()).points;
}

std::pair<double, double> mean_std(const std::vector<double>& v) {
  if (v.empty()) return {NAN, NAN};
  double mean = 0.0;
  for (const double x : v) mean += x / static_cast<double>(v.size());
  double var = 0.0;
  for (const double x : v) var += (x - mean) * (x - mean) / static_cast<double>(std::max<std::size_t>(1, v.size() - 1));
  return {mean, std::sqrt(var)};
}

void run_trial(const fs::path& dir, int frames, std::vector<Cell>& cells) {
  const mlidar::io::Extrinsics truth_file = mlidar::io::read_extrinsics(dir / "groundtruth" / "extrinsics.yaml");
  if (truth_file.find("l2") == nullptr) throw std::runtime_error(dir.string() + ": groundtruth/extrinsics.yaml has no LiDAR l2");
  const SE3 truth = truth_file.find("l2")->T_base_lidar;
  const mlidar::calib::PlanesCalibrator calibrator{mlidar::calib::PlanesConfig{}};
  for (int k = 0; k < frames; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.pcd", k);
    const auto ref = read_points(dir / "scans" / "l1" / name);
    const auto target = read_points(dir / "scans" / "l2" / name);
    Cell& cell = cells[static_cast<std::size_t>(k)];
    try {
      const auto start = std::chrono::steady_clock::now();
      const auto result = calibrator.calibrate(ref, target, std::nullopt, "l1", "l2");
      cell.seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      const double e_r = mlidar::so3_log(truth.rotation() * result.T_ref_target.rotation().conjugate()).norm();
      const double e_t = (truth.translation() - result.T_ref_target.translation()).norm();
      if (e_r > 0.05 || e_t > 0.1) ++cell.failures;
      cell.rotation.push_back(e_r);
      cell.translation.push_back(e_t);
    } catch (const std::exception& e) {
      ++cell.failures;
      std::fprintf(stderr, "%s frame %d: %s\n", dir.c_str(), k, e.what());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int trials = argc > 1 ? std::max(1, std::atoi(argv[1])) : 10;
  const fs::path scratch = argc > 2 ? fs::path(argv[2]) : fs::temp_directory_path() / "mlidar_planes_table";
  const int frames = 7;  // alpha = 60, 70, ..., 120
  std::printf("| Config | alpha [deg] | rot. mean [rad] | rot. std | trans. mean [m] | trans. std | failures | median time [s] |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const int configuration : {1, 2}) {
    std::vector<Cell> cells(frames);
    for (int trial = 0; trial < trials; ++trial) {
      mlidar::sim::CornerSpec spec;
      spec.seed = static_cast<std::uint64_t>(1000 * configuration + trial);
      spec.configuration = configuration;
      char folder[64];
      std::snprintf(folder, sizeof(folder), "c%d_s%d", configuration, trial);
      const fs::path dir = scratch / folder;
      fs::remove_all(dir);
      mlidar::sim::write_corner_dataset(spec, dir);
      run_trial(dir, frames, cells);
      fs::remove_all(dir);
    }
    for (int k = 0; k < frames; ++k) {
      const Cell& cell = cells[static_cast<std::size_t>(k)];
      const auto [r_mean, r_std] = mean_std(cell.rotation);
      const auto [t_mean, t_std] = mean_std(cell.translation);
      std::vector<double> seconds = cell.seconds;
      std::sort(seconds.begin(), seconds.end());
      const double median = seconds.empty() ? NAN : seconds[seconds.size() / 2];
      std::printf("| %d | %d | %.4f | %.4f | %.4f | %.4f | %d/%d | %.3f |\n", configuration, 60 + 10 * k, r_mean, r_std, t_mean, t_std,
                  cell.failures, trials, median);
    }
  }
  return 0;
}
