#pragma once
// Online calibration in the detector's loop (the thesis's "(OC)" rows of Table 6.2 and Fig 6.5): before a frame's
// points are fused, each LiDAR's extrinsic is registered anew against the reference LiDAR's scan of the same frame,
// from the extrinsic in use, with `calibrate refine`'s point-to-plane ICP (calib::refine_pair; no multi-start search:
// the perturbations of 6.6.1.3 are at most a few degrees). A trusted registration replaces the extrinsic and its
// covariance replaces the perturbation prior in tr(Xi) (eq 6.7); an untrusted one leaves both as they were.
#include "mlidar/calib/pair_refine.hpp"
#include "mlidar/core/pose_uncertainty.hpp"
#include "mlidar/core/types.hpp"

namespace mlidar::detect {

struct RefinedExtrinsic {
  /// The refined extrinsic when trusted, else the one given; with the registration's covariance as a left perturbation.
  UncertainPose uncertain_extrinsic;
  calib::PairRefineResult registration;
  bool trusted() const { return calib::is_trusted(registration.verdict); }  ///< it passed refine_pair's checks
};

/// Online calibration's registration: `calibrate refine`'s without the search, lighter (see the .cpp for the numbers).
calib::PairRefineConfig online_refine_config();

/// Registers `lidar` (its own frame) to `reference` (its own frame) from T_base_lidar_given; the reference's extrinsic
/// is taken as exact (it defines the base frame).
RefinedExtrinsic refine_extrinsic_online(const Scan& reference, const SE3& T_base_reference, const Scan& lidar,
                                         const SE3& T_base_lidar_given, const calib::PairRefineConfig& config);

}  // namespace mlidar::detect
