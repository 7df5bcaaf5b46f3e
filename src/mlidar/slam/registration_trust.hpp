#pragma once
// When to believe a scan-to-map registration, and which of several to keep.
// A registration is acceptable when enough of its features matched and its
// matches are tight in absolute terms; it is trusted when, in addition, its
// mean |r| is not far above that of the recent registered frames: a wrong
// alignment of the same kind of scene fits worse than the right ones do (real
// BALM keyframes 56, 105 and 113: 3.3-3.7 x the recent median, 2.5-3.6 deg
// off, while every right one lies within 2 x). After retries from several
// starts the candidate with the tightest matches is kept; it is ambiguous when
// another one as tight (within ambiguity_ratio) lies elsewhere (BALM
// keyframes 110 -> 112 at 1 s: two alignments 2.1 m apart, 0.051 and
// 0.076 m, the first retry to pass was the wrong one).
#include <cstddef>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include "mlidar/slam/scan_to_map.hpp"

namespace mlidar::slam {

struct TrustConfig {
  double min_match_ratio = 0.5;       ///< acceptable: at least this share of features matched
  /// ... or this share for the second frame, whose map is the first sweep alone, when its fit is tight and well
  /// conditioned (converged, not degenerate, mean |r| at most first_max_residual_m): a 16-beam sweep leaves a
  /// feature between its rings with too few neighbours for a plane (one RS-LiDAR-16 at 7.5 m/s: 0.46-0.47 matched
  /// at the second frame, mean |r| 0.027 m, observability 0.21-0.27; 0.58-0.78 at the next frames; lost at 0.5, the
  /// velocity never became known and every later frame was lost too). Wrong second frames after 120-180 deg turns
  /// match 0.37-0.41 but at 0.13-0.15 m, observability 0.006.
  double first_match_ratio = 0.3;
  double first_max_residual_m = 0.06;
  double max_mean_residual_m = 0.2;   ///< acceptable: mean |r| at most this
  double residual_ratio = 2.0;        ///< trusted: mean |r| at most this x the recent median ...
  double residual_floor_m = 0.03;     ///< ... or at most this, whichever is larger
  std::size_t residual_history = 10;  ///< registered frames the recent median is taken over
  /// Until the history holds this many, there is no recent median to judge by, and a registration is trusted only
  /// up to history_free_max_residual_m (else suspect): without it any acceptable fit was trusted. One RS-LiDAR-16 at
  /// 7.5 m/s whose first 0.8 s of scans were missing registered its next frame 1.8 m off at mean |r| 0.19 m, trusted
  /// (right second frames: 0.015-0.03 m on the simulated rigs; docs/benchmarks.md "Frames lost in a row").
  std::size_t min_residual_history = 3;
  double history_free_max_residual_m = 0.06;
  /// Voxel samples (the front end's fallback) fit this much looser than
  /// range-image features of the same scene when the map holds both (real
  /// BALM keyframe 21: 0.031 m for its voxel samples alone, about 0.024 m for
  /// its range-image features): a frame's mean |r| is compared with the recent
  /// ones scaled by 1 + (ratio - 1) x its share of voxel samples, so a run
  /// whose front end changes between frames judges each by its kind.
  double voxel_residual_ratio = 1.3;
  double ambiguity_ratio = 1.15;        ///< a rival within this x the best's mean |r| ...
  double distinct_translation_m = 0.2;  ///< ... farther than this ...
  double distinct_rotation_deg = 2.0;   ///< ... or turned more than this makes the best ambiguous
  /// A degenerate registration (translation observability below the
  /// registration's degeneracy_threshold) that moved the pose farther than
  /// this from its prediction is suspect: its geometry does not pin the
  /// correction it made (simulated solid-state keyframes: the wrong ones slid
  /// metres and tens of degrees along ground-dominated matches, at
  /// observability 0.006-0.05 against 0.13-0.55 for right ones).
  double degenerate_max_correction_m = 0.3;
  double degenerate_max_correction_deg = 3.0;
};

enum class Trust {
  kTrusted,     ///< fits like the recent frames; mapped
  kResidual,    ///< suspect: fits clearly worse than the recent frames
  kAmbiguous,   ///< suspect: another alignment elsewhere fits as well
  kDegenerate,  ///< suspect: degenerate, and it moved far from the prediction
  kLost,        ///< not acceptable at all
};

const char* trust_name(Trust trust);

/// The median mean |r| of the last registrations.
class ResidualHistory {
 public:
  explicit ResidualHistory(std::size_t capacity) : capacity_(capacity) {}
  void add(double mean_residual_m);
  /// NaN before the first.
  double median_m() const;
  std::size_t size() const { return values_.size(); }

 private:
  std::size_t capacity_;
  std::deque<double> values_;
};

struct TrustRule {
  TrustConfig config;
  double recent_median_m;        ///< NaN: no history yet (then trusted up to history_free_max_residual_m)
  bool first_sweep_map = false;  ///< the map holds the first frame alone (TrustConfig::first_match_ratio)

  bool acceptable(const RegistrationResult& r) const;
  bool trusted(const RegistrationResult& r) const;
  /// The largest mean |r| a trusted registration may have (history_free_max_residual_m without history).
  double trusted_limit_m() const;
};

struct Choice {
  std::size_t best = 0;
  Trust trust = Trust::kLost;
  std::optional<std::size_t> rival;  ///< with kAmbiguous: the other alignment
};

/// Keeps the acceptable candidate with the smallest mean |r| (the first one
/// when none is acceptable) and judges it. Candidates must not be empty.
Choice choose_registration(std::span<const RegistrationResult> candidates, const TrustRule& rule);

/// The end poses of coarse registrations worth refining, in order: all but
/// those that converged with a mean |r| above `max_mean_residual_m` (a fit no
/// registration may keep, at a local minimum); the one with the smallest mean
/// |r| always. Candidates must not be empty.
std::vector<SE3> refinable_poses(std::span<const RegistrationResult> coarse, double max_mean_residual_m);

/// The poses in order, each left out when it lies within both `translation_m`
/// and `rotation_deg` of one kept before it (the same alignment reached twice).
std::vector<SE3> distinct_poses(std::span<const SE3> poses, double translation_m, double rotation_deg);

/// kDegenerate when `trust` is kTrusted but the registration is degenerate and
/// moved farther from `prediction` than TrustConfig allows; `trust` otherwise.
Trust judge_degenerate_correction(Trust trust, const RegistrationResult& r, const SE3& prediction, const TrustConfig& config);

}  // namespace mlidar::slam
