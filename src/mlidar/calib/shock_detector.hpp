#pragma once
// Re-calibration trigger (the thesis's extrinsic shock, Sec. 4.9.4 / Table
// 4.6): a LiDAR whose mounting moves registers its features against the map
// worse from then on, while the others do not. Per LiDAR and frame the score
// is the log of its mean registration residual over the median residual of
// the other LiDARs at that frame (relative_to_others, >= 2 LiDARs; the log of
// the residual itself otherwise), so a drift or step common to all LiDARs
// (scene, speed) cancels, and the log makes the test scale-free. A robust
// baseline (median m and MAD of the last `history` normal scores) flags a
// frame as high when
//   score > m + max(threshold_mads * 1.4826 MAD, log(1 + min_relative_jump));
// `consecutive` high frames in a row fire the trigger (a single-frame spike
// does not), after which the LiDAR's baseline is relearnt. High frames are
// kept out of the baseline; normal ones enter it, so a slow drift of one
// LiDAR's score is followed, not flagged.
// The base LiDAR defines the base frame: a trigger on it means the others
// moved relative to it; the caller decides what to restart then.
#include <cstddef>
#include <deque>
#include <span>
#include <vector>

namespace mlidar::calib {

struct ShockDetectorConfig {
  std::size_t history = 50;         ///< normal scores kept per LiDAR for the baseline
  std::size_t min_history = 20;     ///< no decision before the baseline holds this many
  double threshold_mads = 4.0;      ///< robust z-score above which a frame is high
  double min_relative_jump = 0.25;  ///< and at least this relative rise of the residual (ratio)
  std::size_t consecutive = 5;      ///< k: high frames in a row that fire the trigger
  bool relative_to_others = true;   ///< score = residual / median of the other LiDARs' residuals
};

struct ShockLidarState {
  std::deque<double> baseline;  ///< recent normal scores, oldest first
  std::size_t high_run = 0;     ///< high frames in a row so far
  double last_score = 0.0;      ///< log residual (ratio) of the last frame with a score
  double last_limit = 0.0;      ///< the high threshold at the last decision (0 while learning)
  std::size_t triggers = 0;
};

class ShockDetector {
 public:
  /// Throws std::invalid_argument for no LiDARs or a config out of range.
  ShockDetector(std::size_t lidar_count, ShockDetectorConfig config = {});

  /// One frame: the mean registration residual (m) of each LiDAR's features
  /// against the map, in LiDAR order; NaN (or <= 0) marks a LiDAR without
  /// a scan this frame, which is skipped. Returns the LiDARs whose trigger
  /// fired at this frame. Throws std::invalid_argument on a size mismatch.
  std::vector<std::size_t> update(std::span<const double> mean_residual_m);

  /// Forgets LiDAR `lidar`'s baseline (after its re-calibration, say).
  void reset(std::size_t lidar);
  const ShockLidarState& lidar(std::size_t index) const { return lidars_.at(index); }

 private:
  bool decide(ShockLidarState& state, double score) const;

  ShockDetectorConfig config_;
  std::vector<ShockLidarState> lidars_;
};

}  // namespace mlidar::calib
