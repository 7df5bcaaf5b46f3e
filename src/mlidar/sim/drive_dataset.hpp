#pragma once
// `mlidar simulate drive`: simulates a rig moving through a scene and writes
// the dataset folder (io/dataset.hpp):
//   dataset.yaml, times.txt, scans/NAME/NNNNNN.pcd (binary PCD: x y z
//   intensity ring t, t = seconds from the frame stamp, points in the LiDAR
//   frame at their firing time), groundtruth/trajectory.tum (T_world_base at
//   each stamp), groundtruth/extrinsics.yaml (true T_base_lidar),
//   groundtruth/boxes/ (scenes with labelled objects; see ground_truth.hpp),
//   groundtruth/surfaces.ply (with DriveSpec::surface_spacing_m).
// Frame k is stamped start + k * frame_period. The same spec and seed give
// byte-identical files.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "mlidar/io/pcd.hpp"
#include "mlidar/sim/rig.hpp"
#include "mlidar/sim/trajectory.hpp"

namespace mlidar::sim {

struct DriveSpec {
  SimRig rig;
  std::string scene = "campus";
  SimTrajectory trajectory;
  int frames = 100;
  std::uint64_t seed = 1;
  /// Initial extrinsics in dataset.yaml: each non-identity true T_base_lidar
  /// perturbed by a rotation of perturb_deg about a random axis and a
  /// translation of perturb_m in a random direction (seeded).
  double perturb_deg = 0.0;
  double perturb_m = 0.0;
  /// The scans' PCD encoding (binary_compressed: about a third smaller, a little slower to write and read).
  io::PcdEncoding encoding = io::PcdEncoding::kBinary;
  /// > 0: also groundtruth/surfaces.ply, the scenery's exact hits one per cube of this edge (m), in the frame of the
  /// base at the first frame (the frame a run's map.ply is in), with normals (sim/surface_sampler.hpp).
  double surface_spacing_m = 0.0;
};

/// Called after each frame with (frames done, total).
using ProgressFn = std::function<void(int, int)>;

/// Writes the dataset into the folder `out` (created when missing; meant to be new or empty: the CLI gives an
/// io::RunFolder's staging folder, which makes the dataset appear whole or not at all). The spec is checked
/// before anything is written: UsageError for zero frames or a trajectory too short.
void write_drive_dataset(const DriveSpec& spec, const std::filesystem::path& out, const ProgressFn& progress = {});

}  // namespace mlidar::sim
