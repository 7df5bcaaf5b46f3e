#pragma once
// `mlidar calibrate auto`: a start for the refinement when hand-eye's cannot
// be confirmed (issue 25). Bumper LiDARs (short range, mounted low, little
// overlap with the roof unit) have weak odometry of their own, so hand-eye's
// translation can be metres off (lyft on the street: 10-18 m) and the
// refinement from it finds nothing to register. The appearance decides
// instead, as in `calibrate refine` (calib/coarse_search.hpp), but against the
// base's local map rather than one base scan, over a few frames of the drive:
//   1. for search frame k the reference is the base's features of frames
//      k - map_window .. k + map_window in the base frame at k: the drive fills
//      in the near field the roof unit cannot see from one place;
//   2. the ground fixes roll, pitch and the height (a large target plane onto
//      the reference's ground); the yaw is swept over a full turn and the
//      in-plane translation over a grid about the guess, or about the base
//      LiDAR when the guess lies farther than mount_radius_m from it (both are
//      on one vehicle);
//   3. each start is scored by the fraction of the target's points that lie
//      off the reference ground and have a reference point within
//      score_radius_m (the ground matches under any yaw, so it does not vote),
//      first on a quarter of the points, the best `screened` again on all; the
//      best `finalists` are registered point-to-plane (short ICP);
//   4. every registered finalist of every frame is scored again on all search
//      frames; the best summed score is the start, the runner-up is reported.
// Deterministic: fixed frames, starts in a fixed order, ties kept in order.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/calib/coarse_search.hpp"
#include "mlidar/calib/point_to_plane_icp.hpp"
#include "mlidar/calib/ref_surface.hpp"
#include "mlidar/pipelines/autocalib_refine.hpp"

namespace mlidar::pipelines {

struct StartSearchConfig {
  std::size_t frames = 4;             ///< search frames, spread evenly over the candidate frames
  int map_window = 10;                ///< base frames either side of k in the reference
  double mount_radius_m = 6.0;        ///< a guess farther than this from the base LiDAR (in-plane) is not searched about
  double target_voxel_m = 0.3;        ///< target scan thinned to this
  double min_range_m = 1.0;           ///< nearer target points (the vehicle's body) are dropped
  std::size_t score_points = 200;     ///< target points scored per start
  double score_radius_m = 1.0;        ///< step 3's matching distance for the starts
  double final_score_radius_m = 0.3;  ///< step 4's, after registration
  double ground_band_m = 0.3;         ///< points nearer the reference ground than this do not vote
  std::size_t screened = 400;         ///< per frame, best starts on a quarter of the points scored again on all
  std::size_t finalists = 10;         ///< per frame
  calib::CoarseSearchConfig coarse{.yaw_step_deg = 10.0, .xy_radius_m = 5.0, .xy_step_m = 1.0};
  calib::IcpConfig icp{.levels = {{0.5, 2.0, 0.5}, {0.3, 0.8, 0.15}, {0.2, 0.4, 0.05}}, .max_iterations = 10, .max_points = 1500};
  calib::SurfaceConfig surface;
};

struct StartSearchResult {
  std::optional<SE3> T_base_target;  ///< nullopt: no search frame had a reference ground and target points
  std::string label;                 ///< the winning start: frame and coarse start
  double score = 0.0;                ///< its mean step-4 score over the search frames
  double runner_up_score = 0.0;      ///< best score of a finalist distinct from the winner (2 deg / 0.2 m)
  std::vector<std::size_t> frames;   ///< the search frames used
  std::size_t starts_per_frame = 0;
};

/// Searches the start of the refinement for one target LiDAR; `guess` is hand-eye's (or --init's) when there is one.
StartSearchResult search_refine_start(const BaseLocalMaps& base, const TargetFrames& target, const std::optional<SE3>& guess,
                                      const StartSearchConfig& config);

/// One target LiDAR calibrated by its appearance against the base's local maps, the same way in `calibrate auto`
/// and in `slam --calibrate online` (issue 25): the refinement from the motion's start when there is one; when it
/// fails, or there is none, the refinement from the appearance search's start.
struct AppearanceCalibration {
  std::optional<RefineResult> from_start;   ///< the refinement from `start`, when given
  std::optional<StartSearchResult> search;  ///< run when from_start is absent or not ok (and the search is on)
  std::optional<RefineResult> from_search;  ///< the refinement from the search's start, when it found one
  /// The refinement that decides: from_search when it ran, else from_start; null when neither ran.
  const RefineResult* result() const;
  bool ok() const { return result() != nullptr && result()->verdict == RefineVerdict::ok; }
};

/// `search`: null for no search.
AppearanceCalibration calibrate_by_appearance(const BaseLocalMaps& base, const TargetFrames& target, const std::optional<SE3>& start,
                                              const RefineConfig& refine, const StartSearchConfig* search);

}  // namespace mlidar::pipelines
