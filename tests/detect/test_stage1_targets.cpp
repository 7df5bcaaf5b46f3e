// Stage 1's inputs and targets: the BEV pillar grid and the anchors' labels and residuals, checked by hand.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/detect/anchor_targets.hpp"
#include "mlidar/detect/bev_grid.hpp"
#include "mlidar/eval/box_iou.hpp"

namespace mlidar::detect {
namespace {

using io::Box3D;

BevGridConfig small_grid() { return {-4.0, 4.0, -2.0, 2.0, -3.0, 3.0, 0.5}; }  // 16 columns x 8 rows

TEST(BevGrid, PillarFeaturesAreTheMeansOfTheirPoints) {
  const BevGridConfig config = small_grid();
  // Two points in the pillar of column 9 (x in [0.5, 1)), row 4 (y in [0, 0.5)); one outside in z; one outside in x.
  const std::vector<Vec3> points = {{0.6, 0.1, -1.0}, {0.8, 0.3, 0.5}, {0.7, 0.2, 3.5}, {4.2, 0.0, 0.0}};
  const std::vector<float> intensity = {10.0f, 30.0f, 99.0f, 99.0f};
  const std::vector<double> uncertainty = {0.01, 0.03, 9.0, 9.0};
  const BevGrid grid = make_bev_grid(points, intensity, uncertainty, config);
  ASSERT_EQ(grid.rows, 8);
  ASSERT_EQ(grid.cols, 16);
  EXPECT_EQ(grid.counts[4 * 16 + 9], 2U);
  EXPECT_EQ(std::count(grid.counts.begin(), grid.counts.end(), 0U), 8 * 16 - 1);
  EXPECT_NEAR(grid.at(kMeanX, 4, 9), 0.7 - 0.75, 1e-6);  // the pillar's centre is (0.75, 0.25)
  EXPECT_NEAR(grid.at(kMeanY, 4, 9), 0.2 - 0.25, 1e-6);
  EXPECT_NEAR(grid.at(kMeanZ, 4, 9), -0.25, 1e-6);
  EXPECT_NEAR(grid.at(kMaxZ, 4, 9), 0.5, 1e-6);
  EXPECT_NEAR(grid.at(kMinZ, 4, 9), -1.0, 1e-6);
  EXPECT_NEAR(grid.at(kMeanIntensity, 4, 9), 20.0, 1e-5);
  EXPECT_NEAR(grid.at(kMeanUncertainty, 4, 9), 0.02, 1e-7);
  EXPECT_NEAR(grid.at(kLogCount, 4, 9), std::log(3.0), 1e-6);
  EXPECT_EQ(grid.at(kMeanZ, 0, 0), 0.0f);
}

TEST(BevGrid, EdgesAndBadInput) {
  const BevGridConfig config = small_grid();
  EXPECT_FALSE(BevGrid::cell_of(4.0, 0.0, config));  // the upper bound is outside
  EXPECT_EQ(BevGrid::cell_of(-4.0, -2.0, config), (std::pair{0, 0}));
  EXPECT_FALSE(BevGrid::cell_of(std::nan(""), 0.0, config));
  const std::vector<Vec3> nan_point = {{std::nan(""), 0.0, 0.0}, {0.0, 0.0, std::nan("")}};
  const BevGrid empty = make_bev_grid(nan_point, {}, {}, config);
  EXPECT_EQ(std::count(empty.counts.begin(), empty.counts.end(), 0U), 8 * 16);
  EXPECT_THROW(make_bev_grid(nan_point, std::vector<float>(1), {}, config), std::invalid_argument);
  BevGridConfig bad = config;
  bad.cell = 0.0;
  EXPECT_THROW(make_bev_grid({}, {}, {}, bad), std::invalid_argument);
}

TEST(AnchorTargets, ResidualsRoundTripUpToAHalfTurn) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> offset(-2.0, 2.0), size(0.5, 6.0), yaw(-3.14, 3.14);
  const Box3D anchor{Vec3(10.0, -4.0, 0.0), 3.9, 1.6, 1.56, std::numbers::pi / 2};
  for (int trial = 0; trial < 200; ++trial) {
    const Box3D box{Vec3(10.0 + offset(rng), -4.0 + offset(rng), 0.1 * offset(rng)), size(rng), size(rng), size(rng), yaw(rng)};
    const AnchorResidual r = encode_anchor(box, anchor);
    EXPECT_GE(r[6], -std::numbers::pi / 2);
    EXPECT_LT(r[6], std::numbers::pi / 2);
    const Box3D back = decode_anchor(r, anchor);
    EXPECT_NEAR(eval::iou_3d(back, box), 1.0, 1e-9);  // the same box, perhaps turned by 180°
    EXPECT_NEAR(std::remainder(back.yaw - box.yaw, std::numbers::pi), 0.0, 1e-9);
  }
}

TEST(AnchorTargets, ResidualByHand) {
  // Anchor 3.9 x 1.6 x 1.56 at (0, 0), bottom 0, yaw 0; box 4.2 x 1.8 x 1.5 at (1, 0.5), bottom 0.1, yaw 100°.
  // d_a = √(3.9² + 1.6²) = 4.2154; Δz = (0.85 − 0.78) / 1.56; Δθ = 100° − 180° = −80°.
  const Box3D anchor{Vec3(0.0, 0.0, 0.0), 3.9, 1.6, 1.56, 0.0};
  const Box3D box{Vec3(1.0, 0.5, 0.1), 4.2, 1.8, 1.5, 100.0 * std::numbers::pi / 180.0};
  const AnchorResidual r = encode_anchor(box, anchor);
  const double d = std::sqrt(3.9 * 3.9 + 1.6 * 1.6);
  const AnchorResidual expected = {1.0 / d, 0.5 / d, 0.07 / 1.56, std::log(4.2 / 3.9), std::log(1.8 / 1.6), std::log(1.5 / 1.56),
                                   -80.0 * std::numbers::pi / 180.0};
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(r[k], expected[k], 1e-12) << k;
}

TEST(AnchorTargets, ACarOnAnAnchorIsPositiveItsNeighboursIgnoredOrNegative) {
  // Head cells of 0.8 m (0.4 m BEV cells, stride 2) over [-8, 8) x [-8, 8): 20 x 20 cells, anchors at odd multiples
  // of 0.4 m. A car of the anchor's size exactly on the anchor at (0.4, 0.4), yaw 0.
  const BevGridConfig grid{-8.0, 8.0, -8.0, 8.0, -3.0, 3.0, 0.4};
  const AnchorConfig anchors;
  const Box3D car{Vec3(0.4, 0.4, 0.0), 3.9, 1.6, 1.56, 0.0};
  const AnchorTargets targets = assign_anchors(std::span(&car, 1), grid, anchors);
  ASSERT_EQ(targets.rows, 20);
  ASSERT_EQ(targets.cols, 20);
  const auto index = [&](int row, int col, int yaw) { return (static_cast<std::size_t>(row) * 20 + col) * 2 + yaw; };
  EXPECT_EQ(targets.label[index(10, 10, 0)], 1);
  EXPECT_EQ(targets.matched_box[index(10, 10, 0)], 0);
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(targets.residual[index(10, 10, 0)][k], 0.0, 1e-12);
  // One cell along x: the footprints overlap over 3.1 of 3.9 m: IoU 3.1 / 4.7 = 0.66 >= 0.6, positive too.
  EXPECT_EQ(targets.label[index(10, 11, 0)], 1);
  // Two cells along x: 2.3 / 5.5 = 0.42 < 0.45: negative. One cell along y: 0.8 / 2.4 = 0.33: negative.
  EXPECT_EQ(targets.label[index(10, 12, 0)], 0);
  EXPECT_EQ(targets.label[index(11, 10, 0)], 0);
  // Turned 90°, the anchor on the car overlaps it in a 1.6 x 1.6 square: 2.56 / (2 * 6.24 - 2.56) = 0.26: negative.
  EXPECT_EQ(targets.label[index(10, 10, 1)], 0);
  EXPECT_EQ(targets.positives(), 3);  // (10, 9), (10, 10), (10, 11)
  EXPECT_EQ(targets.label[index(10, 9, 0)], 1);
}

TEST(AnchorTargets, EveryBoxGetsItsBestAnchorEvenWhenNoneReachesThePositiveIou) {
  // A pedestrian-sized box under car anchors: the best IoU is small, yet one anchor must learn it.
  const BevGridConfig grid{-8.0, 8.0, -8.0, 8.0, -3.0, 3.0, 0.4};
  const Box3D pedestrian{Vec3(2.0, -3.0, 0.0), 0.8, 0.6, 1.7, 0.3};
  const AnchorTargets targets = assign_anchors(std::span(&pedestrian, 1), grid, AnchorConfig{});
  EXPECT_EQ(targets.positives(), 1);
  const auto positive = std::find(targets.label.begin(), targets.label.end(), std::int8_t{1}) - targets.label.begin();
  EXPECT_EQ(targets.matched_box[static_cast<std::size_t>(positive)], 0);
  EXPECT_EQ(std::count(targets.label.begin(), targets.label.end(), std::int8_t{-1}), 0);
}

}  // namespace
}  // namespace mlidar::detect
