// MLOD's stage-2 geometry: eq 6.12-6.13 canonical points and eq 6.14 residuals, checked by hand and round trips.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/detect/box_coding.hpp"
#include "mlidar/detect/proposal_points.hpp"

namespace mlidar::detect {
namespace {

using io::Box3D;

Box3D random_box(std::mt19937& rng) {
  std::uniform_real_distribution<double> position(-40.0, 40.0), size(0.4, 6.0), yaw(-std::numbers::pi, std::numbers::pi);
  return {Vec3(position(rng), position(rng), 0.05 * position(rng)), size(rng), size(rng), size(rng), yaw(rng)};
}

void expect_same_box(const Box3D& a, const Box3D& b) {
  EXPECT_NEAR((a.center_bottom - b.center_bottom).norm(), 0.0, 1e-9);
  EXPECT_NEAR(a.length, b.length, 1e-9);
  EXPECT_NEAR(a.width, b.width, 1e-9);
  EXPECT_NEAR(a.height, b.height, 1e-9);
  EXPECT_NEAR(std::remainder(a.yaw - b.yaw, 2.0 * std::numbers::pi), 0.0, 1e-9);
}

TEST(BoxCoding, ProposalCornersAndCentreLandOnTheCanonicalCube) {
  // A 4 x 2 x 1.5 box at (10, 5), bottom at z = -1, turned 90°: its length runs along base y.
  const Box3D proposal{Vec3(10.0, 5.0, -1.0), 4.0, 2.0, 1.5, std::numbers::pi / 2};
  EXPECT_NEAR(to_canonical(Vec3(10.0, 5.0, -0.25), proposal).norm(), 0.0, 1e-12);  // the centre
  // The front (along the length: +y here), left (+x turned: -x here), top corner.
  const Vec3 corner = to_canonical(Vec3(10.0 - 1.0, 5.0 + 2.0, 0.5), proposal);
  EXPECT_NEAR(corner.x(), 0.5, 1e-12);
  EXPECT_NEAR(corner.y(), 0.5, 1e-12);
  EXPECT_NEAR(corner.z(), 0.5, 1e-12);
}

TEST(BoxCoding, CanonicalPointsRoundTrip) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 10.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Box3D proposal = random_box(rng);
    const Vec3 p(noise(rng), noise(rng), noise(rng));
    EXPECT_NEAR((from_canonical(to_canonical(p, proposal), proposal) - p).norm(), 0.0, 1e-9);
  }
}

TEST(BoxCoding, ResidualOfTheProposalItselfIsZeroWithCosineOne) {
  const Box3D proposal{Vec3(3.0, -2.0, 0.1), 4.5, 1.9, 1.6, 0.8};
  const Residual u = encode(proposal, proposal);
  for (int k = 0; k < 7; ++k) EXPECT_NEAR(u[k], 0.0, 1e-12) << k;
  EXPECT_NEAR(u[7], 1.0, 1e-12);
}

TEST(BoxCoding, ResidualByHand) {
  // eq 6.14 on numbers: proposal 4 x 2 x 1.5 at centre (0, 0, 0.75), yaw 0; box 5 x 1.8 x 1.5 at centre (1, 0.5, 0.9),
  // yaw 30°: u = [1/4, 0.5/2, 0.15/1.5, 1/4, -0.2/2, 0, sin 30°, cos 30°].
  const Box3D proposal{Vec3(0.0, 0.0, 0.0), 4.0, 2.0, 1.5, 0.0};
  const Box3D box{Vec3(1.0, 0.5, 0.15), 5.0, 1.8, 1.5, std::numbers::pi / 6};
  const Residual u = encode(box, proposal);
  const Residual expected = {0.25, 0.25, 0.1, 0.25, -0.1, 0.0, 0.5, std::sqrt(3.0) / 2};
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(u[k], expected[k], 1e-12) << k;
}

TEST(BoxCoding, EncodeThenDecodeGivesTheBoxBack) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 500; ++trial) {
    const Box3D proposal = random_box(rng), box = random_box(rng);
    expect_same_box(decode(encode(box, proposal), proposal), box);
  }
}

TEST(BoxCoding, DecodeAcceptsAYawPairOfAnyNorm) {
  // A network's (sin, cos) need not be unit: only the angle counts.
  const Box3D proposal{Vec3(0.0, 0.0, 0.0), 4.0, 2.0, 1.5, 3.0};
  const Box3D box = decode({0, 0, 0, 0, 0, 0, 0.3, 0.3}, proposal);
  EXPECT_NEAR(box.yaw, std::remainder(3.0 + std::numbers::pi / 4, 2.0 * std::numbers::pi), 1e-12);
  EXPECT_GT(box.yaw, -std::numbers::pi);
  EXPECT_LE(box.yaw, std::numbers::pi);
}

TEST(ProposalPoints, KeepsThePointsInsideTheGrownBoxWithTheirUncertainty) {
  // A line of points along base x every 0.5 m from -10 to 10 at the height of the box's centre; the proposal is 4 m
  // long at the origin, grown by 2 m each way: |x| <= 4 m, i.e. 17 points.
  const Box3D proposal{Vec3(0.0, 0.0, -0.75), 4.0, 2.0, 1.5, 0.0};
  std::vector<Vec3> cloud;
  std::vector<double> uncertainty;
  for (int k = -20; k <= 20; ++k) {
    cloud.emplace_back(0.5 * k, 0.0, 0.0);
    uncertainty.push_back(0.001 * (k + 20));
  }
  cloud.emplace_back(0.0, 3.01, 0.0);  // beyond the grown width (1 + 2 m)
  cloud.emplace_back(0.0, 0.0, 2.76);  // above the grown top (0.75 + 2 m)
  uncertainty.insert(uncertainty.end(), {1.0, 1.0});
  const ProposalPoints points = proposal_points(cloud, uncertainty, proposal);
  ASSERT_EQ(points.indices.size(), 17U);
  EXPECT_EQ(points.indices.front(), 12U);  // x = -4
  EXPECT_NEAR(points.canonical.front().x(), -1.0, 1e-12);  // -4 m over a 4 m length
  EXPECT_NEAR(points.uncertainty.front(), 0.012, 1e-12);
  EXPECT_TRUE(proposal_points(cloud, {}, proposal).uncertainty.front() == 0.0);
  EXPECT_THROW(proposal_points(cloud, std::vector<double>(3, 0.0), proposal), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::detect
