// Result fusion (eq 6.11): NMS on 3D IoU against the IoU oracle, boxes moved into the base frame, temperature scaling.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/detect/result_fusion.hpp"
#include "mlidar/eval/box_iou.hpp"

namespace mlidar::detect {
namespace {

using io::Box3D;
using io::LabelledBox;
using io::ObjectClass;

LabelledBox car(double x, double y, double yaw, double score, ObjectClass object_class = ObjectClass::kCar) {
  return {object_class, Box3D{Vec3(x, y, 0.0), 4.0, 2.0, 1.5, yaw}, score, 0};
}

TEST(NonMaximumSuppression, KeepsTheBestOfOverlappingBoxesOfOneClass) {
  // b overlaps a by 1/3 (half a length along the heading) and scores higher; c lies elsewhere; d is a pedestrian on a.
  const std::vector<LabelledBox> boxes = {car(0, 0, 0, 0.6), car(2, 0, 0, 0.9), car(20, 0, 0, 0.3),
                                          car(0, 0, 0, 0.8, ObjectClass::kPedestrian)};
  EXPECT_EQ(non_maximum_suppression(boxes, 0.25), (std::vector<std::size_t>{1, 3, 2}));
  EXPECT_EQ(non_maximum_suppression(boxes, 0.34), (std::vector<std::size_t>{1, 3, 0, 2}));  // 1/3 is below 0.34
}

TEST(NonMaximumSuppression, AgreesWithTheIouOracleOnRandomScenes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> position(-8.0, 8.0), yaw(-3.1, 3.1), score(0.0, 1.0);
  for (int scene = 0; scene < 30; ++scene) {
    std::vector<LabelledBox> boxes;
    for (int k = 0; k < 25; ++k) boxes.push_back(car(position(rng), position(rng), yaw(rng), score(rng)));
    const std::vector<std::size_t> kept = non_maximum_suppression(boxes, 0.1);
    std::vector<bool> is_kept(boxes.size(), false);
    for (const std::size_t k : kept) is_kept[k] = true;
    for (std::size_t a = 0; a < kept.size(); ++a)
      for (std::size_t b = a + 1; b < kept.size(); ++b) EXPECT_LE(eval::iou_3d(boxes[kept[a]].box, boxes[kept[b]].box), 0.1);
    for (std::size_t d = 0; d < boxes.size(); ++d) {
      if (is_kept[d]) continue;  // every dropped box overlaps a kept box that scores at least as high
      bool explained = false;
      for (const std::size_t k : kept)
        explained |= *boxes[k].score >= *boxes[d].score && eval::iou_3d(boxes[k].box, boxes[d].box) > 0.1;
      EXPECT_TRUE(explained) << scene << " " << d;
    }
  }
}

TEST(ResultFusion, ABoxOfALidarFrameLandsWhereTheBaseSeesIt) {
  // The LiDAR sits at (3, 1, 0.5) turned 90° about z: its x is the base's y. A car 10 m ahead of it along its x,
  // heading along its x, is 10 m along base y from it, heading along base y.
  const SE3 T_base_lidar(Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ())), Vec3(3.0, 1.0, 0.5));
  const Box3D in_base = to_base(Box3D{Vec3(10.0, 0.0, -1.0), 4.0, 2.0, 1.5, 0.0}, T_base_lidar);
  EXPECT_NEAR((in_base.center_bottom - Vec3(3.0, 11.0, -0.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(in_base.yaw, std::numbers::pi / 2, 1e-12);
  EXPECT_EQ(in_base.length, 4.0);
}

TEST(ResultFusion, TwoLidarsSeeingOneCarGiveOneBoxWithTheBetterCalibratedScore) {
  // One car at base (20, 0). LiDAR a at the origin; LiDAR b 2 m to the left, yawed 10°; each detects the car in its
  // own frame. b's detector is overconfident (temperature 3): its 0.95 becomes σ(logit(0.95) / 3) = 0.7263 < a's 0.8.
  const SE3 T_base_a;
  const SE3 T_base_b(Quat(Eigen::AngleAxisd(0.1745, Vec3::UnitZ())), Vec3(0.0, 2.0, 0.0));
  const Box3D truth{Vec3(20.0, 0.0, 0.0), 4.0, 2.0, 1.5, 0.2};
  const Vec3 centre_in_b = T_base_b.inverse() * Vec3(20.0, 0.0, 0.75);
  const Box3D seen_by_b{centre_in_b - Vec3(0.0, 0.0, 0.75), 4.0, 2.0, 1.5, 0.2 - 0.1745};
  const std::vector<LidarDetections> lidars = {
      {T_base_a, {{ObjectClass::kCar, truth, 0.8, 0}}, 1.0},
      {T_base_b, {{ObjectClass::kCar, seen_by_b, 0.95, 0}, car(-15, 5, 0, 0.5)}, 3.0}};
  const std::vector<LabelledBox> fused = fuse_results(lidars, 0.5);
  ASSERT_EQ(fused.size(), 2U);
  EXPECT_NEAR(*fused[0].score, 0.8, 1e-12);  // a's box wins the car
  EXPECT_NEAR(eval::iou_3d(fused[0].box, truth), 1.0, 1e-9);
  EXPECT_NEAR(*fused[1].score, 0.5, 1e-12);  // σ(0 / 3) = 0.5: the other car, alone
}

TEST(TemperatureScaling, RecoversTheTemperatureThatMadeTheLabels) {
  // Labels drawn with P(positive) = σ(z / 2.5) from logits z ~ N(0, 4²): the fit finds T = 2.5.
  std::mt19937 rng(5);
  std::normal_distribution<double> logit(0.0, 4.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<double> logits;
  std::vector<std::uint8_t> positive;
  for (int k = 0; k < 40000; ++k) {
    logits.push_back(logit(rng));
    positive.push_back(uniform(rng) < 1.0 / (1.0 + std::exp(-logits.back() / 2.5)) ? 1 : 0);
  }
  EXPECT_NEAR(fit_temperature(logits, positive), 2.5, 0.1);
  // Labels that agree with the logits exactly as σ(z) says need no change.
  for (std::size_t k = 0; k < logits.size(); ++k) positive[k] = uniform(rng) < 1.0 / (1.0 + std::exp(-logits[k])) ? 1 : 0;
  EXPECT_NEAR(fit_temperature(logits, positive), 1.0, 0.05);
}

}  // namespace
}  // namespace mlidar::detect
