#pragma once
// One online-calibration window of an auxiliary LiDAR (thesis eq 4.21): its
// features (own frame) on the last frames, whose poses T_world_base the local
// map fixes, are matched against that map at the current extrinsic and the
// window is solved for T_base_lidar alone; correspondences are re-found at
// each gate in turn (coarse to fine). The extrinsic information (J^T J of the
// map terms, the poses being fixed) is Algorithm 1's input.
#include <span>
#include <vector>

#include "mlidar/slam/map_correspondences.hpp"

namespace mlidar::slam {

/// The LiDAR's features at one window frame and the base pose there (map world).
struct CalibrationFrame {
  LidarFrameFeatures features;
  SE3 T_world_base;
};

struct CalibrationWindowResult {
  bool solved = false;             ///< false: fewer than 6 correspondences at some gate
  SE3 T_base_lidar;                ///< the estimate (the start when not solved)
  Mat6 information = Mat6::Zero(); ///< of the extrinsic, [t, r], left perturbation in the base frame
  MapFit fit;                      ///< of the correspondences at the last gate
  /// Residual variance per row at the solution, 2 F / (rows - 6) (F: the
  /// Huber cost, a plane one row, an edge two): sigma^2 with which
  /// sigma^2 information^-1 is the window's own covariance of the estimate.
  double residual_variance_m2 = 0.0;
};

/// `gates_m`: correspondence gates (m), one re-matching pass each; `huber_delta_m`: the window's Huber scale.
CalibrationWindowResult solve_calibration_window(std::span<const CalibrationFrame> frames, const SE3& T_base_lidar, const MapView& map,
                                                 std::span<const double> gates_m, double huber_delta_m);

}  // namespace mlidar::slam
