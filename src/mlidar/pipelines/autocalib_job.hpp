#pragma once
// `mlidar calibrate auto` (thesis Chap. 3). Stage "handeye": every LiDAR's own
// odometry over a dataset folder (slam::Odometry with that LiDAR alone),
// motion pairs A_k = T_{a_{k-s} a_k}, B_k = T_{b_{k-s} b_k} between frames s
// apart, hand-eye per auxiliary LiDAR against the base (calib/hand_eye.hpp),
// and under planar motion the height from the ground planes
// (calib/ground_height.hpp). Stage "refine": the appearance refinement of
// each auxiliary LiDAR against the base's local maps (autocalib_refine.hpp).
// Stage "all" (the default): hand-eye, then refine from its result. Frames
// come from io::FrameSource, read once for every stage (autocalib_refine.hpp).
// Starting extrinsics (--init): required by "refine", refused by "handeye";
// under "all" hand-eye still runs and is reported, and --init is the refine
// start only for LiDARs whose hand-eye result is unusable (degenerate motion,
// planar motion without a ground), so a poor drive can still be refined.
// Writes, each file atomically:
//   RUN/extrinsics.yaml     every LiDAR (base identity), with covariance: the
//                           refined result where refine ran, else hand-eye's
//   RUN/calibration.json    per LiDAR: "handeye" (pairs used / rejected, singular
//                           values, verdict, estimate, ground step), "refine"
//                           (frames tried, overlap ratios, candidate errors, kept,
//                           estimate, covariances, verdict), final estimate;
//                           skipped_scans (frame_gaps.hpp)
// The result does not depend on the order the dataset lists its LiDARs.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mlidar/calib/ground_height.hpp"
#include "mlidar/calib/hand_eye.hpp"
#include "mlidar/pipelines/autocalib_refine.hpp"
#include "mlidar/pipelines/autocalib_search.hpp"
#include "mlidar/pipelines/base_frame.hpp"
#include "mlidar/pipelines/frame_gaps.hpp"

namespace mlidar::pipelines {

/// Which stages run: hand-eye alone, refine alone (from --init) or both.
enum class AutoCalibStage { handeye, refine, all };
std::string_view to_string(AutoCalibStage stage);  ///< "handeye", "refine", "all"
/// Where a LiDAR's refinement started: search is the appearance search (autocalib_search.hpp), run when
/// the refinement from hand-eye's or --init's start failed, or when there was neither.
enum class RefineStart { none, handeye, init, search };
std::string_view to_string(RefineStart start);  ///< "", "handeye", "init", "search"

struct AutoCalibJob {
  std::filesystem::path bag;         ///< a bag instead of a dataset folder (io/bag_frames.hpp)
  io::BagSourceOptions bag_options;  ///< its topics, base, extrinsics, models
  std::filesystem::path dataset;
  std::string base;  ///< empty: the dataset's base
  AutoCalibStage stage = AutoCalibStage::all;
  std::filesystem::path init;                  ///< starting extrinsics YAML (empty: none)
  int pair_stride = 5;                         ///< frames between the two ends of a motion pair
  int ground_frames = 10;                      ///< frames (evenly spaced) used for the ground planes
  int threads = 0;                             ///< worker threads (0: all cores)
  double max_base_gaps = kDefaultMaxBaseGaps;  ///< share of frames the base LiDAR may lack a usable scan in
  calib::HandEyeConfig hand_eye;
  calib::GroundHeightConfig ground;
  RefineConfig refine;
  bool search = true;  ///< search a start when the refinement from hand-eye's or --init's fails (or there is none)
  StartSearchConfig start_search;
  std::filesystem::path out;
};

struct LidarCalibration {
  std::string name;
  SE3 T_base_lidar;  ///< final: refined where refine ran, else hand-eye's
  Mat6 covariance = Mat6::Zero();
  bool handeye_ran = false;
  SE3 T_base_lidar_handeye;  ///< the hand-eye stage's result (after the ground step)
  Mat6 covariance_handeye = Mat6::Zero();
  calib::HandEyeResult hand_eye;                 ///< empty for the base
  RefineStart refine_start = RefineStart::none;  ///< none: refine did not run
  std::optional<RefineResult> refine;
  std::optional<RefineResult> refine_unsearched;     ///< the failed refinement from hand-eye's or --init's start, when a search followed
  RefineStart unsearched_start = RefineStart::none;  ///< where that one started
  std::optional<StartSearchResult> search;
  std::optional<calib::GroundHeightResult> ground;  ///< run under planar motion
  std::size_t odometry_lost_frames = 0;
  /// false: not calibrated (hand-eye unusable and no --init, or the refinement that checks it failed); then
  /// extrinsics.yaml holds `given` (no covariance) or leaves the LiDAR out, and the command exits 1
  bool usable = true;
  std::string reason;        ///< why not calibrated, in words; empty when usable
  std::string advice;        ///< what to try then
  std::optional<SE3> given;  ///< the input's extrinsic (--init, else dataset.yaml's initial_extrinsic)
};

struct AutoCalibSummary {
  std::string base;                      ///< the LiDAR the others are calibrated against (--base, else the one placing the base frame)
  BaseFrame frame;                       ///< the frame extrinsics.yaml is written in (the dataset's base frame; --base's LiDAR when given)
  std::vector<LidarCalibration> lidars;  ///< dataset order
  double seconds = 0.0;
  std::vector<std::string> gaps;            ///< per LiDAR with skipped or missing scans, in words
  std::optional<std::string> base_failure;  ///< the base LiDAR lacked too many frames (exit 1)
  bool all_usable() const;
};

/// UsageError for bad options (unknown base or stage, stride < 1, --init missing
/// for "refine" or given to "handeye"); InputError for bad files.
AutoCalibSummary run_autocalib_job(const AutoCalibJob& job, const std::function<void(const std::string&, int, int)>& progress = {});

}  // namespace mlidar::pipelines
