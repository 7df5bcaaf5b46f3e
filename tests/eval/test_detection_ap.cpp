// KITTI-style AP against precision/recall curves worked out by hand, and the ignore rules (no points, beyond the
// difficulty's range, duplicates).
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/eval/detection_ap.hpp"

namespace mlidar::eval {
namespace {

using io::LabelledBox;
using io::ObjectClass;

LabelledBox car_at(double x, double y, std::optional<double> score = std::nullopt, double yaw = 0.3) {
  return {ObjectClass::kCar, {{x, y, -1.7}, 4.4, 1.8, 1.5, yaw}, score, 0};
}

const DifficultyResult& car_result(const DetectionEvalResult& result, Difficulty d, IouLevel level = IouLevel::kStrict) {
  return result.classes.at(0).levels[static_cast<int>(level)].difficulties[static_cast<int>(d)];
}

DetectionEvalConfig cars_only() {
  DetectionEvalConfig config;
  config.classes = {ObjectClass::kCar};
  return config;
}

// Four cars within 20 m, A-D, over two frames; detections by score:
//   0.9 A (TP), 0.8 A again shifted 0.2 m (a duplicate: FP), 0.7 B (TP), 0.6 nothing there (FP), 0.5 C (TP); D missed.
// Cumulative: (R, P) = (1/4, 1), (1/4, 1/2), (2/4, 2/3), (2/4, 2/4), (3/4, 3/5).
// p_interp(r) = max P at recall >= r: 1 for r <= 1/4, 2/3 for r <= 1/2, 3/5 for r <= 3/4, 0 above.
//   R40, r = i/40: i 1-10 -> 1, 11-20 -> 2/3, 21-30 -> 3/5, 31-40 -> 0: AP = (10 + 20/3 + 6) / 40 = 0.5666...
//   R11, r = i/10: i 0-2 -> 1, 3-5 -> 2/3, 6-7 -> 3/5, 8-10 -> 0:      AP = (3 + 2 + 1.2) / 11 = 0.5636...
// Objects that must not count sit around them: a car at 60 m detected at 0.95 (beyond every range: ignored with its
// detection), a detection at 70 m with no car (0.99, ignored), a car no LiDAR hit detected at 0.85 (ignored).
std::vector<DetectionFrame> hand_made_frames() {
  DetectionFrame first{.id = "000000",
                       .ground_truth = {car_at(10, 0), car_at(0, 12), car_at(60, 5), car_at(-6, 4)},
                       .points_total = {80, 40, 3, 0},
                       .predictions = {car_at(10, 0, 0.9), car_at(10.2, 0, 0.8), car_at(0, 12, 0.7), car_at(60, 5, 0.95),
                                       car_at(-6, 4, 0.85), car_at(-70, 0, 0.99)}};
  DetectionFrame second{.id = "000001",
                        .ground_truth = {car_at(-8, -8), car_at(5, -15)},
                        .points_total = {},
                        .predictions = {car_at(-8, -8, 0.5), car_at(15, 5, 0.6)}};
  return {first, second};
}

TEST(DetectionAp, HandComputedCurveGivesR40AndR11) {
  const DetectionEvalResult result = evaluate_detections(hand_made_frames(), cars_only());
  ASSERT_EQ(result.classes.size(), 1U);
  EXPECT_EQ(result.classes[0].ground_truths, 6);
  EXPECT_EQ(result.classes[0].predictions, 8);
  for (Difficulty d : kDifficulties) {
    const DifficultyResult& r = car_result(result, d);
    EXPECT_EQ(r.ground_truths, 4) << difficulty_name(d);
    for (const ApResult* ap : {&r.box_3d, &r.bev}) {
      EXPECT_EQ(ap->true_positives, 3);
      EXPECT_EQ(ap->false_positives, 2);  // the duplicate and the empty place; the ignored three are neither
      EXPECT_NEAR(ap->ap_r40, (10.0 + 20.0 / 3.0 + 6.0) / 40.0, 1e-12) << difficulty_name(d);
      EXPECT_NEAR(ap->ap_r11, 6.2 / 11.0, 1e-12) << difficulty_name(d);
    }
    ASSERT_EQ(r.box_3d.curve.size(), 5U);
    EXPECT_DOUBLE_EQ(r.box_3d.curve[1].precision, 0.5);
    EXPECT_DOUBLE_EQ(r.box_3d.curve[4].recall, 0.75);
  }
  EXPECT_EQ(result.mean[0][static_cast<int>(Difficulty::kModerate)].classes, 1);
  EXPECT_NEAR(result.mean[0][static_cast<int>(Difficulty::kModerate)].ap3d_r40, (10.0 + 20.0 / 3.0 + 6.0) / 40.0, 1e-12);
}

TEST(DetectionAp, EveryObjectFoundOnceAtTheTopGivesOne) {
  std::vector<DetectionFrame> frames = hand_made_frames();
  frames[1].predictions.push_back(car_at(5, -15, 0.55));  // D found: recall 1, but below two false positives
  DetectionEvalResult result = evaluate_detections(frames, cars_only());
  // (R, P) continue with (4/4, 4/6): r in (3/4, 1] now reaches 2/3 (higher than 3/5, so it lifts (1/2, 3/4] too).
  EXPECT_NEAR(car_result(result, Difficulty::kHard).box_3d.ap_r40, (10.0 + 30.0 * 2.0 / 3.0) / 40.0, 1e-12);
  for (DetectionFrame& frame : frames) {
    std::erase_if(frame.predictions, [](const LabelledBox& p) { return *p.score == 0.8 || *p.score == 0.6; });
  }
  result = evaluate_detections(frames, cars_only());
  EXPECT_DOUBLE_EQ(car_result(result, Difficulty::kHard).box_3d.ap_r40, 1.0);
  EXPECT_DOUBLE_EQ(car_result(result, Difficulty::kHard).box_3d.ap_r11, 1.0);
}

TEST(DetectionAp, DifficultiesAreCumulativeRangesAroundTheVehicle) {
  // Cars at 10 m (ahead), 25 m (behind) and 45 m (to the left), each detected exactly; nothing else.
  const std::vector<DetectionFrame> frames = {{.id = "0",
                                               .ground_truth = {car_at(10, 0), car_at(-25, 0), car_at(0, 45)},
                                               .points_total = {},
                                               .predictions = {car_at(10, 0, 0.9), car_at(-25, 0, 0.8), car_at(0, 45, 0.7)}}};
  const DetectionEvalResult result = evaluate_detections(frames, cars_only());
  EXPECT_EQ(car_result(result, Difficulty::kEasy).ground_truths, 1);
  EXPECT_EQ(car_result(result, Difficulty::kModerate).ground_truths, 2);
  EXPECT_EQ(car_result(result, Difficulty::kHard).ground_truths, 3);
  for (Difficulty d : kDifficulties) {
    // The farther detections match ignored objects: neither true nor false positives, so every AP is 1.
    EXPECT_DOUBLE_EQ(car_result(result, d).box_3d.ap_r40, 1.0) << difficulty_name(d);
    EXPECT_EQ(car_result(result, d).box_3d.false_positives, 0) << difficulty_name(d);
  }
}

TEST(DetectionAp, StrictAndLooseThresholdsSeparateALooseBox) {
  // The detection is shifted by a quarter of the length: 3D IoU = 0.75 / 1.25 = 0.6, between 0.5 and 0.7.
  LabelledBox shifted = car_at(10, 0, 0.9);
  shifted.box.center_bottom += 1.1 * Vec3(std::cos(0.3), std::sin(0.3), 0.0);
  const std::vector<DetectionFrame> frames = {{.id = "0", .ground_truth = {car_at(10, 0)}, .points_total = {}, .predictions = {shifted}}};
  const DetectionEvalResult result = evaluate_detections(frames, cars_only());
  EXPECT_DOUBLE_EQ(car_result(result, Difficulty::kEasy, IouLevel::kStrict).box_3d.ap_r40, 0.0);
  EXPECT_EQ(car_result(result, Difficulty::kEasy, IouLevel::kStrict).box_3d.false_positives, 1);
  EXPECT_DOUBLE_EQ(car_result(result, Difficulty::kEasy, IouLevel::kLoose).box_3d.ap_r40, 1.0);
}

TEST(DetectionAp, WrongClassIsNoMatchAndEmptyClassIsNaN) {
  LabelledBox pedestrian = car_at(10, 0, 0.9);
  pedestrian.object_class = ObjectClass::kPedestrian;
  const std::vector<DetectionFrame> frames = {
      {.id = "0", .ground_truth = {car_at(10, 0)}, .points_total = {}, .predictions = {pedestrian}}};
  const DetectionEvalResult result = evaluate_detections(frames, DetectionEvalConfig{});
  ASSERT_EQ(result.classes.size(), 3U);
  EXPECT_DOUBLE_EQ(car_result(result, Difficulty::kEasy).box_3d.ap_r40, 0.0);
  const DifficultyResult& cyclists = result.classes[2].levels[0].difficulties[0];
  EXPECT_EQ(cyclists.ground_truths, 0);
  EXPECT_TRUE(std::isnan(cyclists.box_3d.ap_r40));
  // The pedestrian detection has no pedestrian to match: one false positive, AP NaN (no ground truth).
  EXPECT_EQ(result.classes[1].levels[0].difficulties[0].box_3d.false_positives, 1);
  EXPECT_EQ(result.mean[0][0].classes, 1);  // only cars had ground truth
}

TEST(DetectionAp, TiedScoresMakeOnePointOfTheCurve) {
  const std::vector<PrPoint> curve = precision_recall_curve({{0.5, true}, {0.9, true}, {0.5, false}, {0.5, true}, {0.2, false}}, 4);
  ASSERT_EQ(curve.size(), 3U);
  EXPECT_DOUBLE_EQ(curve[0].recall, 0.25);
  EXPECT_DOUBLE_EQ(curve[1].recall, 0.75);
  EXPECT_DOUBLE_EQ(curve[1].precision, 0.75);
  EXPECT_DOUBLE_EQ(curve[2].precision, 0.6);
  EXPECT_TRUE(precision_recall_curve({}, 4).empty());
  EXPECT_DOUBLE_EQ(average_precision({}, RecallPoints::kR40), 0.0);
}

TEST(DetectionAp, BadConfigurationIsAUsageError) {
  DetectionEvalConfig config;
  config.classes = {ObjectClass::kCar, ObjectClass::kCar};
  EXPECT_THROW(config.validate(), UsageError);
  config = DetectionEvalConfig{};
  config.thresholds[0].strict = 1.5;
  EXPECT_THROW(config.validate(), UsageError);
  config = DetectionEvalConfig{};
  config.classes.clear();
  EXPECT_THROW(config.validate(), UsageError);
}

TEST(DetectionAp, PredictionWithoutScoreNamesFrameAndLine) {
  LabelledBox unscored = car_at(10, 0);
  unscored.line = 4;
  const std::vector<DetectionFrame> frames = {{.id = "pred/000003.txt", .ground_truth = {}, .points_total = {}, .predictions = {unscored}}};
  try {
    evaluate_detections(frames, cars_only());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pred/000003.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 4"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mlidar::eval
