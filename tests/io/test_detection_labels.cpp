// Base-frame detection labels (label_2 layout) and the simulator's per-frame object JSON: round trips and every
// rejected input naming its file and line.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "format_test_util.hpp"
#include "mlidar/io/detection_labels.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {
using test::expect_input_error;

constexpr const char* kFile = "frames/000007.txt";

LabelledBox labelled(ObjectClass object_class, Vec3 centre, double l, double w, double h, double yaw, std::optional<double> score) {
  return {object_class, {centre, l, w, h, yaw}, score, 0};
}

TEST(DetectionLabels, RoundTripKeepsEveryValueExactly) {
  const std::vector<LabelledBox> boxes = {labelled(ObjectClass::kCar, {12.25, -3.0 / 7.0, -1.7}, 4.5, 1.8, 1.55, 0.1 + 1e-15, std::nullopt),
                                          labelled(ObjectClass::kPedestrian, {-30.0, 2.0, 0.1}, 0.6, 0.7, 1.8, -3.1, 0.875),
                                          labelled(ObjectClass::kCyclist, {0.0, 49.999, 0.0}, 1.8, 0.6, 1.7, 1e-300, 1e-5)};
  const std::string text = format_detection_labels(boxes, kFile);
  EXPECT_EQ(text.substr(0, text.find('\n')), "car 0 0 -10 -1 -1 -1 -1 1.55 1.8 4.5 12.25 -0.42857142857142855 -1.7 0.100000000000001");
  const std::vector<LabelledBox> back = parse_detection_labels(text, kFile, ScoreRule::kOptional);
  ASSERT_EQ(back.size(), boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_EQ(back[i].object_class, boxes[i].object_class);
    EXPECT_EQ(back[i].box.center_bottom, boxes[i].box.center_bottom);
    EXPECT_EQ(back[i].box.length, boxes[i].box.length);
    EXPECT_EQ(back[i].box.width, boxes[i].box.width);
    EXPECT_EQ(back[i].box.height, boxes[i].box.height);
    EXPECT_EQ(back[i].box.yaw, boxes[i].box.yaw);
    EXPECT_EQ(back[i].score, boxes[i].score);
    EXPECT_EQ(back[i].line, static_cast<int>(i) + 1);
  }
}

TEST(DetectionLabels, ReadsKittiCaseAndCameraFieldsAndSkipsBlankLines) {
  const std::string text = "\nPedestrian 0.00 0 -0.20 712.40 143.00 810.73 307.92 1.89 0.48 1.20 1.84 1.47 8.41 0.01\r\n\n";
  const std::vector<LabelledBox> boxes = parse_detection_labels(text, kFile, ScoreRule::kOptional);
  ASSERT_EQ(boxes.size(), 1U);
  EXPECT_EQ(boxes[0].object_class, ObjectClass::kPedestrian);
  EXPECT_EQ(boxes[0].line, 2);
  EXPECT_DOUBLE_EQ(boxes[0].box.height, 1.89);  // h w l
  EXPECT_DOUBLE_EQ(boxes[0].box.width, 0.48);
  EXPECT_DOUBLE_EQ(boxes[0].box.length, 1.20);
  EXPECT_EQ(boxes[0].box.center_bottom, Vec3(1.84, 1.47, 8.41));
  EXPECT_DOUBLE_EQ(boxes[0].box.yaw, 0.01);
  EXPECT_FALSE(boxes[0].score.has_value());
  EXPECT_EQ(object_class_from_name("CYCLIST"), ObjectClass::kCyclist);
  EXPECT_FALSE(object_class_from_name("Van").has_value());
}

/// A valid prediction line with field `column` (0-based) replaced by `value`.
std::string line_with(std::size_t column, const std::string& value) {
  std::vector<std::string> fields = {"car", "0", "0", "-10", "-1", "-1", "-1", "-1", "1.5", "1.8", "4.2", "10", "2", "-1.7", "0.3", "0.9"};
  fields[column] = value;
  std::string line;
  for (const std::string& f : fields) line += f + ' ';
  return line;
}

TEST(DetectionLabels, BadInputNamesFileLineAndField) {
  const std::string good = line_with(0, "car") + "\n";
  const auto rejects = [&](const std::string& bad_line, ScoreRule rule, std::initializer_list<std::string> parts) {
    // The bad line is line 3 (a blank line and a good one before it).
    expect_input_error([&] { parse_detection_labels("\n" + good + bad_line + "\n", kFile, rule); }, parts);
  };
  rejects(line_with(8, "nan"), ScoreRule::kRequired, {kFile, "line 3", "column 9 (height)", "finite"});
  rejects(line_with(12, "inf"), ScoreRule::kRequired, {kFile, "line 3", "column 13 (location y)", "finite"});
  rejects(line_with(9, "-1.8"), ScoreRule::kRequired, {kFile, "line 3", "column 10 (width)", "> 0"});
  rejects(line_with(10, "0"), ScoreRule::kRequired, {kFile, "line 3", "column 11 (length)", "> 0"});
  rejects(line_with(11, "ten"), ScoreRule::kRequired, {kFile, "line 3", "column 12 (location x)"});
  rejects(line_with(0, "Van"), ScoreRule::kRequired, {kFile, "line 3", "column 1 (type)", "Van", "car, pedestrian, cyclist"});
  rejects(line_with(15, "nan"), ScoreRule::kRequired, {kFile, "line 3", "column 16 (score)", "finite"});
  rejects(line_with(2, "0.5"), ScoreRule::kRequired, {kFile, "line 3", "column 3 (occluded)"});
  const std::string without_score = line_with(0, "car").substr(0, line_with(0, "car").rfind("0.9"));
  rejects(without_score, ScoreRule::kRequired, {kFile, "line 3", "column 16 (score)", "needs a score"});
  EXPECT_EQ(parse_detection_labels(without_score, kFile, ScoreRule::kOptional).size(), 1U);
  rejects("car 0 0 -10 -1 -1 -1 -1 1.5 1.8 4.2 10 2", ScoreRule::kOptional, {kFile, "line 3", "found 13"});
  rejects(good.substr(0, good.size() - 1) + " 7", ScoreRule::kOptional, {kFile, "line 3", "found 17"});
}

TEST(LabelledObjects, ReadsClassAndPointsInFileOrder) {
  const std::string json = R"({"frame": "000000", "objects": [
    {"id": 3, "class": "car", "box": {"center_bottom": [1, 2, 0], "size_lwh": [4, 2, 1.5], "yaw": 0.1},
     "points": {"TOP": 120, "FRONT_LEFT": 0}, "points_total": 120, "distance_m": 2.2, "difficulty": "easy"},
    {"id": 5, "class": "Cyclist", "points_total": 0}]})";
  const std::vector<LabelledObjectInfo> objects = parse_labelled_objects(json, "labels/000000.json");
  ASSERT_EQ(objects.size(), 2U);
  EXPECT_EQ(objects[0].object_class, ObjectClass::kCar);
  EXPECT_EQ(objects[0].points_total, 120);
  EXPECT_EQ(objects[1].object_class, ObjectClass::kCyclist);
  EXPECT_EQ(objects[1].points_total, 0);
}

TEST(LabelledObjects, BadJsonNamesFileAndKey) {
  const std::string file = "labels/000004.json";
  expect_input_error([&] { parse_labelled_objects("{\"objects\": [", file); }, {file, "JSON"});
  expect_input_error([&] { parse_labelled_objects("{\"frame\": \"000004\"}", file); }, {file, "objects"});
  expect_input_error([&] { parse_labelled_objects(R"({"objects": [{"class": "car"}]})", file); }, {file, "objects[0].points_total"});
  expect_input_error([&] { parse_labelled_objects(R"({"objects": [{"class": "car", "points_total": -1}]})", file); },
                     {file, "objects[0].points_total"});
  expect_input_error(
      [&] { parse_labelled_objects(R"({"objects": [{"class": "car", "points_total": 1}, {"class": "tram", "points_total": 1}]})", file); },
      {file, "objects[1].class", "tram"});
}

}  // namespace
}  // namespace mlidar::io
