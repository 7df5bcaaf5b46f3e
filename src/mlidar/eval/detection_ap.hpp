#pragma once
// KITTI-style average precision of 3D detections in the base frame (`mlidar eval detections`).
//
// Sources: the KITTI object devkit's evaluate_object.cpp (Geiger et al. 2012: ground truths that must not count are
// "ignored", a detection on an ignored ground truth is neither a true nor a false positive, one detection per ground
// truth, precision interpolated as the largest precision at any higher recall, AP over 11 recall points) with the
// 40-point variant R40 (Simonelli et al. 2019, "Disentangling Monocular 3D Object Detection", now the devkit's
// default); the thesis sec 6.6.1.2 for the difficulties by distance, 360° around the vehicle, instead of KITTI's
// image-based ones: easy < 20 m, moderate < 30 m, hard < 50 m, cumulative (moderate holds the easy objects), and
// for the IoU thresholds (car 0.7 and 0.5; pedestrian and cyclist 0.5 and KITTI's looser 0.25).
//
// Per class, IoU threshold and difficulty d with range R_d:
//   ground truth j is ignored  when its horizontal distance ||(x, y)|| >= R_d or no LiDAR point lies on it;
//   matching, frame by frame, detections by descending score: a detection takes the unmatched non-ignored ground
//     truth of highest IoU >= threshold (a true positive); failing that, it is ignored when it overlaps an ignored
//     ground truth by IoU >= threshold or its own centre lies at >= R_d, and otherwise is a false positive (so a
//     second detection of a matched object is a false positive);
//   over all frames, at each score s: recall(s) = TP(s) / N_d, precision(s) = TP(s) / (TP(s) + FP(s)), N_d the
//     non-ignored ground truths;
//   p_interp(r) = max { precision(s) : recall(s) >= r } (0 when no score reaches recall r);
//   AP_R40 = 1/40 · Σ_{i=1..40} p_interp(i / 40),   AP_R11 = 1/11 · Σ_{i=0..10} p_interp(i / 10).
// With IoU the exact 3D IoU (AP_3D) or the bird's-eye-view IoU (AP_BEV), eval/box_iou.hpp.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mlidar/io/detection_labels.hpp"

namespace mlidar::eval {

enum class Difficulty : std::uint8_t { kEasy, kModerate, kHard };
inline constexpr std::array<Difficulty, 3> kDifficulties = {Difficulty::kEasy, Difficulty::kModerate, Difficulty::kHard};

/// "easy", "moderate", "hard".
std::string difficulty_name(Difficulty difficulty);
/// R_d: objects at a horizontal distance below it belong to the difficulty (20, 30, 50 m; thesis 6.6.1.2).
double difficulty_range_m(Difficulty difficulty);

/// The box overlap a match is measured by.
enum class Overlap : std::uint8_t { kBox3D, kBev };

/// One frame: its ground truth, the points on each ground-truth box, its predictions (each with a score).
struct DetectionFrame {
  std::string id;
  std::vector<io::LabelledBox> ground_truth;
  std::vector<int> points_total;  ///< one per ground-truth box, same order; empty: every box has points
  std::vector<io::LabelledBox> predictions;
};

/// The two IoU thresholds of a class: strict first (car 0.7, others 0.5), then loose.
struct IouThresholds {
  double strict = 0.7;
  double loose = 0.5;
};

/// Car 0.7 / 0.5; pedestrian and cyclist 0.5 / 0.25.
IouThresholds default_iou_thresholds(io::ObjectClass object_class);

/// Which IoU threshold of a class a result is for.
enum class IouLevel : std::uint8_t { kStrict, kLoose };
inline constexpr std::array<IouLevel, 2> kIouLevels = {IouLevel::kStrict, IouLevel::kLoose};
std::string iou_level_name(IouLevel level);  ///< "strict", "loose"

struct DetectionEvalConfig {
  std::vector<io::ObjectClass> classes = {io::kObjectClasses.begin(), io::kObjectClasses.end()};
  /// Indexed by io::ObjectClass.
  std::array<IouThresholds, 3> thresholds = {default_iou_thresholds(io::ObjectClass::kCar),
                                             default_iou_thresholds(io::ObjectClass::kPedestrian),
                                             default_iou_thresholds(io::ObjectClass::kCyclist)};

  double threshold(io::ObjectClass object_class, IouLevel level) const;
  /// UsageError for no class, a class given twice, or a threshold outside (0, 1].
  void validate() const;
};

/// A point of the precision/recall curve: the values counting every detection with score >= `score`.
struct PrPoint {
  double score = 0.0;
  double recall = 0.0;
  double precision = 0.0;
};

/// Recall sample positions: R40 = {1/40, ..., 1}, R11 = {0, 0.1, ..., 1}.
enum class RecallPoints : std::uint8_t { kR40, kR11 };

/// p_interp(r) at each sample position of `points` for a curve of non-decreasing recall.
std::vector<double> interpolated_precision(std::span<const PrPoint> curve, RecallPoints points);
/// The mean of interpolated_precision: AP in [0, 1].
double average_precision(std::span<const PrPoint> curve, RecallPoints points);

/// A detection's fate under one class, threshold and difficulty.
struct ScoredOutcome {
  double score = 0.0;
  bool true_positive = false;
};
/// The curve of outcomes (any order) against `ground_truths` non-ignored objects: one point per distinct score,
/// by descending score. Empty for no outcome or no ground truth.
std::vector<PrPoint> precision_recall_curve(std::vector<ScoredOutcome> outcomes, int ground_truths);

struct ApResult {
  double ap_r40 = 0.0;  ///< [0, 1]; NaN when the difficulty has no ground truth
  double ap_r11 = 0.0;
  int true_positives = 0;   ///< counting every detection
  int false_positives = 0;  ///< counting every detection (ignored ones excluded)
  std::vector<PrPoint> curve;
};

struct DifficultyResult {
  Difficulty difficulty = Difficulty::kEasy;
  int ground_truths = 0;  ///< non-ignored objects
  ApResult box_3d;
  ApResult bev;
};

struct ThresholdResult {
  IouLevel level = IouLevel::kStrict;
  double iou = 0.7;
  std::array<DifficultyResult, 3> difficulties;  ///< indexed by Difficulty
};

struct ClassResult {
  io::ObjectClass object_class = io::ObjectClass::kCar;
  int ground_truths = 0;  ///< boxes of the class in every frame, ignored ones included
  int predictions = 0;
  std::array<ThresholdResult, 2> levels;  ///< indexed by IouLevel
};

/// The mean over the classes with ground truth in that difficulty (NaN, classes 0, when none has).
struct MeanAp {
  int classes = 0;
  double ap3d_r40 = 0.0, ap3d_r11 = 0.0, apbev_r40 = 0.0, apbev_r11 = 0.0;
};

struct DetectionEvalResult {
  int frames = 0;
  std::vector<ClassResult> classes;             ///< in the config's order
  std::array<std::array<MeanAp, 3>, 2> mean{};  ///< [IouLevel][Difficulty]
};

/// Evaluates every frame (InputError for a prediction without a score, naming the frame and line).
DetectionEvalResult evaluate_detections(std::span<const DetectionFrame> frames, const DetectionEvalConfig& config);

}  // namespace mlidar::eval
