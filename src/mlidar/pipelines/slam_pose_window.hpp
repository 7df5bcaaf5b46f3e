#pragma once
// `mlidar slam`'s hook for the sliding window over the trusted poses
// (slam::OdometryWindow, thesis eq 4.22 with N + 1 = window.size + 1 frames,
// pivot window.pivot; on with window.refine_odometry).
//
// Frames 0 and 1 keep the odometry's poses: at frame 1 the odometry moves its
// world to the first stamp and rebuilds its map from both frames (deskewed
// again); the window starts from a copy of that map and takes frames from 2
// on, of which the first p fill its fixed part as given (so frames 0 to
// p + 1 are the odometry's). A lost frame (the odometry could not register
// it) is not added: it keeps the odometry's pose, and its features were not
// mapped.
//
// Output: the pose of frame k is the window's estimate when k leaves the
// variable part (settled: N + 1 - p solves, the last with the frames before
// it in the map); SlamFrame::T_world_base holds the window's latest estimate
// at frame k's time, and SlamFrame::settled revises an earlier frame.
#include <cstddef>
#include <optional>
#include <vector>

#include "mlidar/pipelines/slam_config.hpp"
#include "mlidar/slam/odometry.hpp"
#include "mlidar/slam/odometry_window.hpp"

namespace mlidar::pipelines {

/// The window's settings from `mlidar slam`'s config (window and odometry sections).
slam::OdometryWindowConfig odometry_window_config(const SlamConfig& config);

class SlamPoseWindow {
 public:
  explicit SlamPoseWindow(const SlamConfig& config) : config_(odometry_window_config(config)) {}

  /// After `odometry` processed frame `frame` with `result`; nullopt when
  /// the window does not take the frame (frames 0-1, lost frames).
  std::optional<slam::OdometryWindowUpdate> add(std::size_t frame, const slam::FrameResult& result, const slam::Odometry& odometry);

  /// The frames still in the window's variable part, at their current estimates.
  std::vector<slam::WindowPose> unsettled() const;

 private:
  slam::OdometryWindowConfig config_;
  std::optional<slam::OdometryWindow> window_;
};

}  // namespace mlidar::pipelines
