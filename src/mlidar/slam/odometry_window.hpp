#pragma once
// The sliding window over the trusted poses: M-LOAM's pure-odometry mode
// (thesis eq 4.22, Sec. 4.7) behind the scan-to-map odometry.
//
// The window holds N + 1 frames (oldest first). The first p (Table 4.2: N = 4,
// p = 2) are fixed; the last of them, at index p - 1, is the pivot. Fixed
// frames' features are in the window's local map at their final poses (with
// the settled frames before them, within local_map_radius_m: the thesis's map
// holds the window's frames only). The last N + 1 - p frames are variables:
// every trusted LiDAR's features at those frames (in the base frame at the
// frame's time centroid, i.e. with the fixed extrinsics already applied:
// eq 4.22's T_base_lidar are constants, so all LiDARs' features act as one
// set) are matched against that map, which is attached to the pivot
// (MapAnchor: each term is r(T_pivot^-1 T_k x), eq 4.22), and the window is
// solved (window_solver.hpp) with the pivot held fixed.
// A new frame starts at the window's estimate of the previous frame moved by
// the odometry's relative motion. When the window is full, the pivot is
// marginalized (sec 4.7.5: "x_p is the only state to be marginalized"; eq
// 4.39-4.44, first-estimate Jacobians, marginalization.hpp): every map term
// touches it, so eliminating it leaves a prior on the variable frames' poses
// relative to each other (rank at most 6 (N - p): a motion common to all
// poses and the map moves no residual). Then the window shifts: frame 0 leaves, the frame
// at p moves to p - 1, becomes the new pivot (fixed), its features join the
// map, and its pose is settled (final); the prior now ties the later frames to it.
#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

#include "mlidar/slam/map_correspondences.hpp"
#include "mlidar/slam/voxel_map.hpp"
#include "mlidar/slam/window_solver.hpp"

namespace mlidar::slam {

struct OdometryWindowConfig {
  int size = 4;                  ///< N: the window holds N + 1 frames
  int pivot = 2;                 ///< p: frames 0..p-1 of the window are fixed (1 <= p <= N)
  double gate_m = 0.5;           ///< correspondence gate on |r| (m)
  int min_correspondences = 30;  ///< per variable frame; fewer: the window is not solved
  double plane_voxel_m = 1.0;
  double edge_voxel_m = 1.0;
  int plane_points_per_voxel = 20;
  int edge_points_per_voxel = 10;
  double local_map_radius_m = 100.0;
  RegistrationConfig registration;  ///< plane / line fitting of the map
  WindowSolverConfig solver;
};

/// A pose of frame `frame` as reported: the estimate times the frame's output offset.
struct WindowPose {
  std::size_t frame = 0;
  SE3 T_world_base;
};

struct OdometryWindowUpdate {
  WindowPose latest;                  ///< the frame just added, as the window now estimates it
  std::optional<WindowPose> settled;  ///< the frame that left the variable part (its final pose)
  std::size_t correspondences = 0;    ///< of the last solve (0: not solved)
  int prior_rank = 0;                 ///< rows of the marginalization prior now in the window
};

class OdometryWindow {
 public:
  /// `edge_map` / `plane_map`: the local map to start from (e.g. the
  /// odometry's after its first frames), world frame. Throws
  /// std::invalid_argument for size < 1 or pivot outside [1, size].
  OdometryWindow(OdometryWindowConfig config, VoxelMap edge_map, VoxelMap plane_map);

  /// Adds frame `frame`: `features` in the base frame at the pose
  /// `T_world_base_odometry` given by the odometry; `T_estimate_output` takes
  /// the estimated pose to the reported one (e.g. from the time centroid to
  /// the stamp). Frames in increasing order.
  OdometryWindowUpdate add(std::size_t frame, LidarFrameFeatures features, const SE3& T_world_base_odometry, const SE3& T_estimate_output);

  /// The current estimates of the frames not settled yet (oldest first).
  std::vector<WindowPose> unsettled() const;

 private:
  struct Entry {
    std::size_t frame = 0;
    LidarFrameFeatures features;
    SE3 T_estimate_output;
  };
  WindowPose reported(std::size_t index) const;
  /// Frame `index` becomes fixed: its features join the map at its estimate.
  void settle(std::size_t index);
  std::size_t solve();

  OdometryWindowConfig config_;
  VoxelMap edge_map_;
  VoxelMap plane_map_;
  std::deque<Entry> entries_;  ///< parallel to state_.T_world_base
  WindowState state_;
  WindowProblem problem_;
  std::optional<SE3> last_odometry_pose_;
};

}  // namespace mlidar::slam
