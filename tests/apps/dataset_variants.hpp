#pragma once
// Shared by the CLI tests that run a job twice on one simulated dataset: a
// variant of its folder (the pose differences they compare: pose_error.hpp).
#include <algorithm>
#include <filesystem>
#include <string>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/se3.hpp"
#include "mlidar/core/so3.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "pose_error.hpp"

namespace mlidar::test {

/// A copy of the dataset folder `sim` at `out` (scans shared through a link,
/// ground truth left out) with its LiDARs listed in reverse order and/or the
/// true extrinsics as the initial ones.
inline std::filesystem::path dataset_variant(const std::filesystem::path& sim, const std::filesystem::path& out, bool reverse,
                                             bool true_extrinsics) {
  std::filesystem::create_directories(out);
  io::Dataset dataset = io::read_dataset_yaml(sim / "dataset.yaml");
  if (reverse) std::reverse(dataset.lidars.begin(), dataset.lidars.end());
  if (true_extrinsics) {
    const io::Extrinsics truth = io::read_extrinsics(sim / "groundtruth" / "extrinsics.yaml");
    for (auto& lidar : dataset.lidars) lidar.initial_extrinsic = truth.find(lidar.name)->T_base_lidar;
  }
  dataset.groundtruth = {};
  io::write_dataset_yaml(out / "dataset.yaml", dataset);
  std::filesystem::copy_file(sim / dataset.times, out / dataset.times);
  std::filesystem::create_directory_symlink(std::filesystem::absolute(sim / "scans"), out / "scans");
  return out;
}

/// The simulator's true extrinsics (sim/groundtruth/extrinsics.yaml) with LiDAR `lidar` placed as thesis Table 4.6
/// injects a wrong extrinsic: its rotation turned `deg` about each of its axes (so3_exp([a, a, a]), local) and `m`
/// added along each base axis.
inline io::Extrinsics perturbed_truth(const std::filesystem::path& sim, const std::string& lidar, double deg, double m) {
  io::Extrinsics extrinsics = io::read_extrinsics(sim / "groundtruth" / "extrinsics.yaml");
  const double a = deg_to_rad(deg);
  for (io::LidarExtrinsic& l : extrinsics.lidars)
    if (l.name == lidar)
      l.T_base_lidar = SE3(l.T_base_lidar.rotation() * so3_exp(Vec3(a, a, a)), l.T_base_lidar.translation() + Vec3(m, m, m));
  return extrinsics;
}

}  // namespace mlidar::test
