#pragma once
// Does a given extrinsic agree with the map? A LiDAR mounted other than its
// extrinsic says puts its points where the others' are not: registered with
// the others against their common map, its mean residual stays well above the
// base LiDAR's at every frame, while a right extrinsic keeps it near the
// base's. Per auxiliary LiDAR and frame the ratio of its mean registration
// residual to the base's (the test the calibration window's re-initialization
// uses, StartParams::reinitialize_residual_ratio); the median over the last
// `frames` ratios above `residual_ratio` marks the extrinsic as disagreeing.
// Measured (docs/benchmarks.md "A given extrinsic that disagrees with the
// map"): right extrinsics 0.63-1.03 over any 20 frames on the simulated rhd
// and rv rigs; Table 4.6's 10 deg x 3 / 0.1 m x 3 shock 1.6-5.8.
// Unlike calib::ShockDetector (a change against the LiDAR's own history), this
// needs no healthy start: it judges an extrinsic that was wrong from frame 1.
#include <cstddef>
#include <deque>
#include <optional>
#include <span>
#include <vector>

namespace mlidar::calib {

struct ExtrinsicCheckConfig {
  std::size_t frames = 20;      ///< ratios in the median (a decision needs this many)
  double residual_ratio = 2.0;  ///< median ratio to the base's residual above which an extrinsic disagrees (0: no check at all)
  /// The map test (slam/map_consistency.hpp) after this many frames and again at twice as many each time (30, 60,
  /// 120, ...; 0: never; the odometry job: on its final map): a LiDAR's points map_ratio times farther from the other
  /// LiDARs' planes than from its own disagree. Doubling keeps its cost (about 50 ms for 4 LiDARs) off long runs.
  std::size_t map_first_frames = 30;
  double map_ratio = 3.0;
};

class ExtrinsicCheck {
 public:
  /// Throws std::invalid_argument for no LiDARs, frames == 0 or a negative ratio.
  ExtrinsicCheck(std::size_t lidar_count, ExtrinsicCheckConfig config);

  /// One frame: each LiDAR's mean residual against the map (m), base first; NaN or <= 0 where it had none (a missing
  /// scan, a LiDAR not registered this frame), and `checked[j]` false for a LiDAR whose extrinsic is not to be judged
  /// (the base, a LiDAR being calibrated). Returns the LiDARs whose median ratio crossed the threshold at this frame;
  /// a LiDAR is reported once until reset(). Throws std::invalid_argument on a size mismatch.
  std::vector<std::size_t> update(std::span<const double> mean_residual_m, const std::vector<bool>& checked);
  /// Forgets LiDAR `lidar`'s ratios and verdict (after its extrinsic changed).
  void reset(std::size_t lidar);
  /// The median of LiDAR `lidar`'s last ratios (none before `frames` of them).
  std::optional<double> median_ratio(std::size_t lidar) const;

 private:
  struct LidarState {
    std::deque<double> ratios;  ///< the last `frames`, oldest first
    bool disagreed = false;
  };
  ExtrinsicCheckConfig config_;
  std::vector<LidarState> lidars_;
};

}  // namespace mlidar::calib
