#pragma once
// `mlidar slam --calibrate online`: the appearance start of an auxiliary LiDAR
// (issue 25). The hand-eye on a LiDAR's own odometry cannot start every LiDAR
// of a vehicle: under planar motion the predicted 1 sigma of its translation
// stayed at 0.46 m (rv on campus, seed 5, `left`) and about 1 m (lyft's
// bumper LiDARs on the street), above initialization.translation_max_std_m,
// and those LiDARs never left initialization, while `calibrate auto`
// calibrated them from the same frames by their appearance. So a LiDAR still
// initializing StartParams::appearance_after_frames frames after it began is
// calibrated the way `calibrate auto` does it (calibrate_by_appearance: the
// refinement against the base's local maps from hand-eye's current estimate,
// then from the appearance search's start) on the frames the estimator kept
// since: the base's scans with the trusted poses, and the LiDAR's scans at the
// refinement's candidate frames. An `ok` verdict starts the calibration window
// from its estimate (Algorithm 1 still decides the convergence); any other is
// reported and tried again as many frames later, on the frames kept by then.
#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/pipelines/autocalib_refine.hpp"
#include "mlidar/pipelines/autocalib_search.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {

/// The last frames of a slam run, kept while some LiDAR initializes.
class AppearanceHistory {
 public:
  /// `capacity`: frames kept; `frame_step`: the refinement's candidate spacing (RefineConfig::frame_step): the
  /// auxiliary LiDARs' scans are kept at frames whose index is a multiple of it.
  AppearanceHistory(std::size_t capacity, std::size_t frame_step);

  /// Frame `index` (increasing): the trusted pose, whether the odometry flagged it (lost or suspect), the base's
  /// scan, and `scans[j]` for the LiDARs j that `keep` marks (scans[0] is the base's).
  void add(std::size_t index, double stamp, const SE3& T_world_base, bool flagged, const std::vector<std::optional<Scan>>& scans,
           const std::vector<bool>& keep);
  void clear() { frames_.clear(); }
  bool empty() const { return frames_.empty(); }
  std::size_t frame_step() const { return frame_step_; }

  /// The base's local maps and LiDAR j's frames over the kept frames from `first` on, starting at a candidate
  /// frame (index a multiple of frame_step); nullopt when fewer than two frames remain.
  struct Inputs {
    BaseLocalMaps base;
    TargetFrames target;
    std::size_t first_frame = 0;  ///< the run's index of local frame 0
  };
  std::optional<Inputs> inputs(std::size_t first, const slam::LidarSetup& base, const slam::LidarSetup& lidar, std::size_t j,
                               const RefineConfig& refine) const;

 private:
  struct KeptFrame {
    std::size_t index = 0;
    double stamp = 0.0;
    SE3 T_world_base;
    bool flagged = false;
    std::vector<std::optional<Scan>> scans;  ///< [0] the base's at every frame; the others' at candidate frames
  };
  std::size_t capacity_;
  std::size_t frame_step_;
  std::deque<KeptFrame> frames_;
};

/// One appearance start, for the report.
struct AppearanceAttempt {
  std::size_t frame = 0;        ///< the frame it ran at
  std::size_t frames_used = 0;  ///< kept frames it ran on
  bool ok = false;
  std::string verdict;  ///< the deciding refinement's (RefineVerdict), "no_frames" or "no_start"
  std::string message;  ///< why, in words
  bool searched = false;
  std::string search_label;  ///< the search's winning start, when it ran and found one
  std::optional<SE3> T_base_lidar;
  double seconds = 0.0;
};

/// The refinement of an appearance start: `calibrate auto`'s, except that fused degenerate registrations need
/// only be inside the calibration window's reach (its fine gate 0.3 m at 3 sigma), not be a result (1.5 cm):
/// lyft street seed 2 `front_left` fused to 1.7 cm / 0.04 deg and was refused there twice.
RefineConfig appearance_refine_config();

/// What the appearance start runs with (`calibrate auto`'s search).
struct AppearanceStartConfig {
  RefineConfig refine = appearance_refine_config();
  bool search = true;
  StartSearchConfig start_search;
};

/// LiDAR j calibrated by its appearance on the kept frames from `first` on, from `guess` (hand-eye's current
/// estimate) and, when that fails, from the appearance search's start.
AppearanceAttempt appearance_start(const AppearanceHistory& history, std::size_t first, const slam::LidarSetup& base,
                                   const slam::LidarSetup& lidar, std::size_t j, const SE3& guess, const AppearanceStartConfig& config);

}  // namespace mlidar::pipelines
