#pragma once
// Internal to pipelines/slam_estimator.cpp and slam_start.cpp: one LiDAR's state across frames
// (SlamEstimator::Track) and the constants both files use.
#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "mlidar/pipelines/slam_estimator.hpp"
#include "mlidar/slam/calibration_window.hpp"

namespace mlidar::pipelines {

/// Frames between the two ends of a motion pair (eq 4.13 pairs consecutive
/// frames). Measured on the simulated rhd handheld drive (80 frames, 10 Hz):
/// with consecutive frames sigma_min2 of Q_K reached only 0.13 < sigma_R =
/// 0.25 (rotations of 1-3 deg per frame); pairs 5 frames apart (overlapping,
/// one per frame) rotate 5x more.
constexpr std::size_t kPairStride = 5;
/// Frames of (base, LiDAR) scans kept while initializing for the ground heights (thesis 3.4.3.1) under planar motion.
constexpr std::size_t kGroundFrames = 5;

inline slam::LidarSetup with_extrinsic(slam::LidarSetup setup, const SE3& T_base_lidar) {
  setup.T_base_lidar = T_base_lidar;
  return setup;
}

/// One LiDAR's state across frames.
struct SlamEstimator::Track {
  slam::LidarSetup setup;  ///< T_base_lidar: the current extrinsic
  LidarRole role = LidarRole::initializing;
  calib::OnlineHandEye hand_eye;
  std::unique_ptr<slam::Odometry> own;      ///< its own odometry while initializing
  /// T_g_lidar: the frame g the own odometry runs in is the LiDAR's rotated by
  /// the given extrinsic's rotation (identity when none is given), so that its
  /// ground segmentation knows which way is up (with identity, a LiDAR rolled
  /// 40 deg lost every frame on 2 of 10 seeds); B_k is taken back to the LiDAR
  /// frame, so the hand-eye does not depend on it.
  SE3 T_g_lidar;
  struct PosePair {
    SE3 T_world_lidar;  ///< own odometry
    SE3 T_world_base;   ///< trusted odometry, same frame
  };
  std::deque<PosePair> recent;              ///< the last kPairStride + 1 frames, without gaps
  std::deque<std::pair<Scan, Scan>> ground;  ///< the last kGroundFrames (base, LiDAR) scans while initializing
  std::size_t high_residual_windows = 0;     ///< windows not accepted with a high residual ratio since the last acceptance
  std::size_t rotation_only_pairs = 0;       ///< pairs added in a row with the rotation ready, not the translation
  std::vector<slam::CalibrationFrame> window;  ///< the last N + 1 frames while calibrating
  struct Pending {
    Scan scan;
    double stamp = 0.0;
    SE3 T_world_base;
  };
  std::optional<Pending> pending;  ///< while calibrating: the last scan, deskewed at the next frame
  slam::FrontEndWorkspace workspace;
  slam::LidarFeatures features;
  SlamLidarReport report;

  Track(slam::LidarSetup lidar, calib::OnlineHandEyeConfig config) : setup(std::move(lidar)), hand_eye(config) {}
};

}  // namespace mlidar::pipelines
