#pragma once
// One online-calibration window of an auxiliary LiDAR (thesis eq 4.21): its
// features (own frame) on the last frames, whose poses T_world_base the local
// map fixes, are matched against that map at the current extrinsic and the
// window is solved for T_base_lidar alone; correspondences are re-found at
// each gate in turn (coarse to fine). The extrinsic information (J^T J of the
// map terms, the poses being fixed) is Algorithm 1's input. Re-matching moves
// the estimate, which moves the matches: the last gate is repeated until a
// pass changes the estimate by less than the settle tolerances (measured on
// the simulated room: two passes left windows 2-20 cm from their own
// solution, and those transients biased the mean of L_calib windows by cm).
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
  bool solved = false;              ///< false: fewer than 6 correspondences at some gate
  SE3 T_base_lidar;                 ///< the estimate (the start when not solved)
  Mat6 information = Mat6::Zero();  ///< of the extrinsic, [t, r], left perturbation in the base frame
  MapFit fit;                       ///< of the correspondences at the last gate
  /// Residual variance per row at the solution, 2 F / (rows - 6) (F: the
  /// Huber cost, a plane one row, an edge two): sigma^2 with which
  /// sigma^2 information^-1 is the window's own covariance of the estimate.
  double residual_variance_m2 = 0.0;
  /// The change of the estimate in the last gate's pass (translation m, rotation rad): a window
  /// whose re-matching still moves it has not reached its own solution (a transient).
  double last_step_m = 0.0;
  double last_step_rad = 0.0;
  int passes = 0;        ///< re-matching passes run
  bool settled = false;  ///< the last pass moved it less than the tolerances
};

struct CalibrationWindowOptions {
  /// Correspondence gates (m), one re-matching pass each, coarse to fine: the hand-eye start may be a
  /// degree and centimetres off (0.5 m at 30 m range); the next pass matches at the previous solution.
  std::vector<double> gates_m{1.0, 0.3};
  double huber_delta_m = 0.1;           ///< the window's Huber scale
  int settle_passes = 4;                ///< extra passes at the last gate at most (0: the gates only)
  double settle_translation_m = 0.003;  ///< settled when a pass moves the estimate less than this...
  double settle_rotation_rad = 5e-4;    ///< ... and this (0.029 deg)
};

CalibrationWindowResult solve_calibration_window(std::span<const CalibrationFrame> frames, const SE3& T_base_lidar, const MapView& map,
                                                 const CalibrationWindowOptions& options);

}  // namespace mlidar::slam
