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
#include <string>
#include <vector>

namespace mlidar::calib {

struct ExtrinsicCheckConfig {
  std::size_t frames = 20;      ///< ratios in the median (a decision needs this many)
  double residual_ratio = 2.0;  ///< median ratio to the base's residual above which an extrinsic disagrees (0: no check)
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

/// What showed a given extrinsic wrong: ExtrinsicCheck's median residual ratio, the map test's ratio
/// (slam/map_consistency.hpp) or a start whose frames were all lost, whichever judged it.
struct DisagreementEvidence {
  std::size_t frame = 0;               ///< the frame of the verdict
  double residual_ratio = -1.0;        ///< > 0: judged by ExtrinsicCheck (the median over `frames` frames)
  double map_ratio = -1.0;             ///< > 0: judged by the map test
  bool frames_lost = false;            ///< judged because the frames after the first were all lost (the slam job's start)
  std::string reference = "the base";  ///< whose residual it was divided by, in words ("the reference LiDAR top")
};

/// The evidence in words, one clause for the terminal and report.html, e.g. "at frame 5 its residual was 3.1x the
/// base's, the median of the last extrinsic_check.frames frames; right extrinsics stay near 1".
std::string describe(const DisagreementEvidence& evidence);

}  // namespace mlidar::calib
