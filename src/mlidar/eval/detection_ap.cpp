// KITTI-style AP of 3D detections (definitions and sources in detection_ap.hpp). Written from the definitions,
// not from the devkit's code: the devkit matches again for each score threshold; matching once by descending
// score and sweeping the threshold over the sorted outcomes gives the same counts, since a detection's match
// depends only on the detections scored above it.
#include "mlidar/eval/detection_ap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Core>

#include "mlidar/core/error.hpp"
#include "mlidar/eval/box_iou.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double horizontal_distance(const io::Box3D& box) { return box.center_bottom.head<2>().norm(); }

/// One frame's boxes of one class, prepared once for every threshold and difficulty.
struct ClassFrame {
  std::vector<double> scores;            ///< predictions by descending score
  std::vector<double> prediction_range;  ///< their horizontal distance (m)
  std::vector<double> truth_range;       ///< ground truths' horizontal distance (m)
  std::vector<bool> truth_has_points;
  std::array<Eigen::MatrixXd, 2> iou;  ///< [Overlap](prediction, ground truth)
};

std::vector<const io::LabelledBox*> predictions_by_score(const DetectionFrame& frame, io::ObjectClass object_class) {
  std::vector<const io::LabelledBox*> chosen;
  for (const io::LabelledBox& p : frame.predictions) {
    if (p.object_class != object_class) continue;
    if (!p.score) throw InputError(frame.id, io::line_field(static_cast<std::size_t>(p.line)), "a prediction needs a score");
    chosen.push_back(&p);
  }
  std::stable_sort(chosen.begin(), chosen.end(), [](const auto* a, const auto* b) { return *a->score > *b->score; });
  return chosen;
}

ClassFrame prepare_class_frame(const DetectionFrame& frame, io::ObjectClass object_class) {
  ClassFrame out;
  std::vector<const io::Box3D*> truths;
  for (std::size_t j = 0; j < frame.ground_truth.size(); ++j) {
    if (frame.ground_truth[j].object_class != object_class) continue;
    truths.push_back(&frame.ground_truth[j].box);
    out.truth_range.push_back(horizontal_distance(frame.ground_truth[j].box));
    out.truth_has_points.push_back(frame.points_total.empty() || frame.points_total[j] > 0);
  }
  const std::vector<const io::LabelledBox*> predictions = predictions_by_score(frame, object_class);
  for (Eigen::MatrixXd& m : out.iou) m.resize(static_cast<Eigen::Index>(predictions.size()), static_cast<Eigen::Index>(truths.size()));
  for (std::size_t i = 0; i < predictions.size(); ++i) {
    out.scores.push_back(*predictions[i]->score);
    out.prediction_range.push_back(horizontal_distance(predictions[i]->box));
    for (std::size_t j = 0; j < truths.size(); ++j) {
      const auto r = static_cast<Eigen::Index>(i);
      const auto c = static_cast<Eigen::Index>(j);
      out.iou[static_cast<int>(Overlap::kBox3D)](r, c) = iou_3d(predictions[i]->box, *truths[j]);
      out.iou[static_cast<int>(Overlap::kBev)](r, c) = bev_iou(predictions[i]->box, *truths[j]);
    }
  }
  return out;
}

/// The rule a frame is matched under.
struct MatchRule {
  Overlap overlap = Overlap::kBox3D;
  double iou = 0.7;
  double range_m = 50.0;
};

/// Matches one frame (rule in detection_ap.hpp); appends the counted detections' outcomes, returns the number of
/// non-ignored ground truths.
int match_frame(const ClassFrame& frame, const MatchRule& rule, std::vector<ScoredOutcome>& outcomes) {
  const Eigen::MatrixXd& iou = frame.iou[static_cast<int>(rule.overlap)];
  const std::size_t truths = frame.truth_range.size();
  std::vector<bool> ignored(truths), matched(truths, false);
  int counted = 0;
  for (std::size_t j = 0; j < truths; ++j) {
    ignored[j] = !frame.truth_has_points[j] || frame.truth_range[j] >= rule.range_m;
    counted += ignored[j] ? 0 : 1;
  }
  for (std::size_t i = 0; i < frame.scores.size(); ++i) {
    std::ptrdiff_t best = -1;
    double best_iou = -1.0;
    bool overlaps_ignored = false;
    for (std::size_t j = 0; j < truths; ++j) {
      const double value = iou(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
      if (value < rule.iou) continue;
      if (ignored[j]) {
        overlaps_ignored = true;
      } else if (!matched[j] && value > best_iou) {
        best = static_cast<std::ptrdiff_t>(j);
        best_iou = value;
      }
    }
    if (best >= 0) {
      matched[static_cast<std::size_t>(best)] = true;
      outcomes.push_back({frame.scores[i], true});
    } else if (!overlaps_ignored && frame.prediction_range[i] < rule.range_m) {
      outcomes.push_back({frame.scores[i], false});
    }
  }
  return counted;
}

ApResult average_precision_of(std::vector<ScoredOutcome> outcomes, int ground_truths) {
  ApResult result;
  for (const ScoredOutcome& o : outcomes) (o.true_positive ? result.true_positives : result.false_positives) += 1;
  result.curve = precision_recall_curve(std::move(outcomes), ground_truths);
  result.ap_r40 = ground_truths > 0 ? average_precision(result.curve, RecallPoints::kR40) : kNaN;
  result.ap_r11 = ground_truths > 0 ? average_precision(result.curve, RecallPoints::kR11) : kNaN;
  return result;
}

/// AP of one class under one rule over every frame; `ground_truths` receives N_d.
ApResult evaluate_rule(std::span<const ClassFrame> frames, const MatchRule& rule, int& ground_truths) {
  std::vector<ScoredOutcome> outcomes;
  ground_truths = 0;
  for (const ClassFrame& frame : frames) ground_truths += match_frame(frame, rule, outcomes);
  return average_precision_of(std::move(outcomes), ground_truths);
}

ThresholdResult evaluate_level(std::span<const ClassFrame> frames, IouLevel level, double iou) {
  ThresholdResult result{.level = level, .iou = iou, .difficulties = {}};
  for (Difficulty d : kDifficulties) {
    DifficultyResult& out = result.difficulties[static_cast<int>(d)];
    out.difficulty = d;
    const double range = difficulty_range_m(d);
    out.box_3d = evaluate_rule(frames, {Overlap::kBox3D, iou, range}, out.ground_truths);
    out.bev = evaluate_rule(frames, {Overlap::kBev, iou, range}, out.ground_truths);
  }
  return result;
}

ClassResult evaluate_class(std::span<const DetectionFrame> frames, io::ObjectClass object_class, const DetectionEvalConfig& config) {
  ClassResult result{.object_class = object_class, .ground_truths = 0, .predictions = 0, .levels = {}};
  std::vector<ClassFrame> prepared;
  prepared.reserve(frames.size());
  for (const DetectionFrame& frame : frames) {
    prepared.push_back(prepare_class_frame(frame, object_class));
    result.ground_truths += static_cast<int>(prepared.back().truth_range.size());
    result.predictions += static_cast<int>(prepared.back().scores.size());
  }
  for (IouLevel level : kIouLevels)
    result.levels[static_cast<int>(level)] = evaluate_level(prepared, level, config.threshold(object_class, level));
  return result;
}

/// The mean over the classes with ground truth in (level, difficulty).
MeanAp mean_over_classes(std::span<const ClassResult> classes, IouLevel level, Difficulty difficulty) {
  MeanAp mean;
  for (const ClassResult& c : classes) {
    const DifficultyResult& r = c.levels[static_cast<int>(level)].difficulties[static_cast<int>(difficulty)];
    if (r.ground_truths == 0) continue;
    ++mean.classes;
    mean.ap3d_r40 += r.box_3d.ap_r40;
    mean.ap3d_r11 += r.box_3d.ap_r11;
    mean.apbev_r40 += r.bev.ap_r40;
    mean.apbev_r11 += r.bev.ap_r11;
  }
  const double scale = mean.classes > 0 ? 1.0 / mean.classes : kNaN;
  for (double* value : {&mean.ap3d_r40, &mean.ap3d_r11, &mean.apbev_r40, &mean.apbev_r11}) *value *= scale;
  return mean;
}

}  // namespace

std::string difficulty_name(Difficulty difficulty) {
  switch (difficulty) {
    case Difficulty::kEasy:
      return "easy";
    case Difficulty::kModerate:
      return "moderate";
    case Difficulty::kHard:
      return "hard";
  }
  return "hard";
}

double difficulty_range_m(Difficulty difficulty) {
  switch (difficulty) {
    case Difficulty::kEasy:
      return 20.0;
    case Difficulty::kModerate:
      return 30.0;
    case Difficulty::kHard:
      return 50.0;
  }
  return 50.0;
}

IouThresholds default_iou_thresholds(io::ObjectClass object_class) {
  return object_class == io::ObjectClass::kCar ? IouThresholds{0.7, 0.5} : IouThresholds{0.5, 0.25};
}

std::string iou_level_name(IouLevel level) { return level == IouLevel::kStrict ? "strict" : "loose"; }

double DetectionEvalConfig::threshold(io::ObjectClass object_class, IouLevel level) const {
  const IouThresholds& t = thresholds[static_cast<int>(object_class)];
  return level == IouLevel::kStrict ? t.strict : t.loose;
}

void DetectionEvalConfig::validate() const {
  if (classes.empty()) throw UsageError("no class to evaluate (known: " + io::known_object_classes() + ")");
  for (std::size_t i = 0; i < classes.size(); ++i) {
    if (std::find(classes.begin(), classes.begin() + static_cast<std::ptrdiff_t>(i), classes[i]) !=
        classes.begin() + static_cast<std::ptrdiff_t>(i))
      throw UsageError("class " + io::object_class_name(classes[i]) + " is given twice");
  }
  for (io::ObjectClass c : io::kObjectClasses) {
    for (IouLevel level : kIouLevels) {
      const double t = threshold(c, level);
      if (!(t > 0.0 && t <= 1.0))
        throw UsageError("the " + iou_level_name(level) + " IoU threshold of " + io::object_class_name(c) + " must lie in (0, 1]");
    }
  }
}

std::vector<PrPoint> precision_recall_curve(std::vector<ScoredOutcome> outcomes, int ground_truths) {
  std::vector<PrPoint> curve;
  if (ground_truths <= 0) return curve;
  std::sort(outcomes.begin(), outcomes.end(), [](const ScoredOutcome& a, const ScoredOutcome& b) { return a.score > b.score; });
  int true_positives = 0;
  for (std::size_t k = 0; k < outcomes.size(); ++k) {
    true_positives += outcomes[k].true_positive ? 1 : 0;
    // One point per distinct score: every detection at that score is in or out together.
    if (k + 1 < outcomes.size() && outcomes[k + 1].score == outcomes[k].score) continue;
    const double counted = static_cast<double>(k + 1);
    curve.push_back({outcomes[k].score, static_cast<double>(true_positives) / ground_truths, true_positives / counted});
  }
  return curve;
}

std::vector<double> interpolated_precision(std::span<const PrPoint> curve, RecallPoints points) {
  // best_from[k] = max precision over curve[k..]: p_interp at any r in (recall[k-1], recall[k]].
  std::vector<double> best_from(curve.size() + 1, 0.0);
  for (std::size_t k = curve.size(); k-- > 0;) best_from[k] = std::max(best_from[k + 1], curve[k].precision);
  const int count = points == RecallPoints::kR40 ? 40 : 11;
  std::vector<double> precision;
  precision.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double r = points == RecallPoints::kR40 ? (i + 1) / 40.0 : i / 10.0;
    const auto first = std::lower_bound(curve.begin(), curve.end(), r, [](const PrPoint& p, double value) { return p.recall < value; });
    precision.push_back(best_from[static_cast<std::size_t>(first - curve.begin())]);
  }
  return precision;
}

double average_precision(std::span<const PrPoint> curve, RecallPoints points) {
  const std::vector<double> precision = interpolated_precision(curve, points);
  return std::accumulate(precision.begin(), precision.end(), 0.0) / static_cast<double>(precision.size());
}

DetectionEvalResult evaluate_detections(std::span<const DetectionFrame> frames, const DetectionEvalConfig& config) {
  config.validate();
  DetectionEvalResult result;
  result.frames = static_cast<int>(frames.size());
  for (io::ObjectClass c : config.classes) result.classes.push_back(evaluate_class(frames, c, config));
  for (IouLevel level : kIouLevels) {
    for (Difficulty d : kDifficulties)
      result.mean[static_cast<int>(level)][static_cast<int>(d)] = mean_over_classes(result.classes, level, d);
  }
  return result;
}

}  // namespace mlidar::eval
