#pragma once
// `mlidar perturb`: a copy of a dataset whose extrinsics are perturbed as in
// thesis 6.6.1.3 (eq 6.1-6.2 with eq 6.8's prior scaled by alpha, every
// component bounded at its sigma), for testing detection and mapping under
// extrinsic perturbation. Starting from the true extrinsics (the dataset's
// groundtruth/extrinsics.yaml, else its dataset.yaml), every LiDAR but the one
// that defines the base frame gets one perturbation drawn from the seed. The
// copy holds:
//   dataset.yaml                 the perturbed extrinsics as initial_extrinsic; everything else as given
//   scans, times, groundtruth/   copied (or hard-linked with `link`), unchanged
//   groundtruth/extrinsics.yaml  the true extrinsics (written from dataset.yaml when the source had none)
//   groundtruth/perturbation.json  alpha, seed, sigmas and, per LiDAR, the drawn rho (m) and phi (rad)
//   extrinsics_perturbed.yaml    the perturbed extrinsics with the prior's covariance (extrinsics.yaml's
//                                [t additive, r local] tangent), for `--extrinsics` and the detectors
//   fused/NNNNNN.pcd             with `fused`: each frame's points of every LiDAR in the base frame through
//                                the perturbed extrinsics (not deskewed), fields x y z intensity lidar
//                                (index in dataset order) uncertainty (tr(Xi) of eq 6.7, m^2)
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "mlidar/core/extrinsic_perturbation.hpp"

namespace mlidar::pipelines {

struct PerturbSpec {
  PerturbationPrior prior;  ///< alpha and eq 6.8's sigmas
  std::uint64_t seed = 1;
  bool fused = false;  ///< also write fused/ clouds with the per-point uncertainty
  bool link = false;   ///< hard-link the copied files (a copy where the file system cannot)
};

struct PerturbedLidar {
  std::string name;
  SE3 T_base_lidar_true;
  SE3 T_base_lidar_perturbed;
  bool perturbed = false;  ///< false for the LiDAR that defines the base frame
};

/// Writes the perturbed copy of the dataset at `dataset` into `out` (new or empty: the CLI gives a RunFolder's
/// staging folder). InputError naming the file and LiDAR for a LiDAR with no extrinsic to start from, or
/// ground-truth extrinsics of another base. `progress(done, total)` after each fused frame.
std::vector<PerturbedLidar> write_perturbed_dataset(const std::filesystem::path& dataset, const PerturbSpec& spec,
                                                    const std::filesystem::path& out, const std::function<void(int, int)>& progress = {});

}  // namespace mlidar::pipelines
