// Trajectories (TUM, KITTI poses, BALM CSV) and 4x4 transform files.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "format_test_util.hpp"
#include "mlidar/io/pose_covariance_io.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "pose_error.hpp"
#include "test_support.hpp"

namespace mlidar::io {
namespace {
using test::expect_input_error;

Trajectory random_trajectory(unsigned seed, std::size_t n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  Trajectory trajectory;
  double stamp = 1630577758.569490;
  for (std::size_t i = 0; i < n; ++i) {
    Vec6 xi;
    for (int k = 0; k < 6; ++k) xi(k) = uniform(rng) * (k < 3 ? 100.0 : 1.0);
    stamp += 0.1 + 0.01 * std::abs(uniform(rng));
    trajectory.poses.push_back({stamp, SE3::exp(xi)});
  }
  return trajectory;
}

using mlidar::test::rotation_error_rad;

void expect_close(const Trajectory& expected, const Trajectory& actual, double tolerance, bool same_stamps) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    if (same_stamps) {
      EXPECT_EQ(actual.poses[i].stamp, expected.poses[i].stamp);
    }
    EXPECT_LT((actual.poses[i].T_world_base.translation() - expected.poses[i].T_world_base.translation()).norm(), tolerance);
    EXPECT_LT(rotation_error_rad(actual.poses[i].T_world_base, expected.poses[i].T_world_base), tolerance);
  }
}

TEST(TrajectoryRoundTrip, TumAndKittiWithin1e12) {
  const auto dir = test::scratch_dir();
  const Trajectory trajectory = random_trajectory(3, 50);
  write_tum(dir / "t.tum", trajectory);
  expect_close(trajectory, read_tum(dir / "t.tum"), 1e-12, true);

  write_kitti_poses(dir / "t.kitti", trajectory);
  std::vector<double> stamps;
  for (const auto& pose : trajectory.poses) stamps.push_back(pose.stamp);
  expect_close(trajectory, read_kitti_poses(dir / "t.kitti", stamps), 1e-12, true);
  const Trajectory indexed = read_kitti_poses(dir / "t.kitti");
  EXPECT_EQ(indexed.poses[7].stamp, 7.0);
}

TEST(PoseCovarianceFile, RoundTripsTheUpperTriangleExactly) {
  const auto dir = test::scratch_dir();
  std::mt19937_64 rng(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<StampedCovariance> written;
  for (int k = 0; k < 5; ++k) {
    const Mat6 A = Mat6::NullaryExpr([&] { return normal(rng); });
    written.push_back({0.1 * k + 1e9, A * A.transpose() * 1e-4});
  }
  write_pose_covariances(dir / "pose_covariance.txt", written);
  const std::vector<StampedCovariance> read = read_pose_covariances(dir / "pose_covariance.txt");
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t k = 0; k < read.size(); ++k) {
    EXPECT_EQ(read[k].stamp, written[k].stamp);
    EXPECT_EQ(read[k].covariance, written[k].covariance) << k;  // exact digits, symmetric
  }
}

TEST(PoseCovarianceFile, ABadLineNamesTheFileAndLine) {
  expect_input_error([] { parse_pose_covariances("# header\n1 2 3\n", "pc.txt"); }, {"pc.txt", "line 2", "expected 22 values"});
  std::string nan_line = "1";
  for (int k = 0; k < 21; ++k) nan_line += k == 4 ? " nan" : " 0";
  expect_input_error([&] { parse_pose_covariances(nan_line + "\n", "pc.txt"); }, {"pc.txt", "line 1", "finite"});
}

TEST(TumReader, SkipsCommentsAndNormalisesSixDigitQuaternions) {
  const Trajectory t = parse_tum("# t x y z qx qy qz qw\n\n  \n1.0 1 2 3 0 0 0.707107 0.707107\n# end\n2.0 1 2 3 0 0 0 1\n", "t.tum");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_NEAR(t.poses[0].T_world_base.rotation().norm(), 1.0, 1e-15);
  EXPECT_NEAR(t.poses[0].T_world_base.rotation().z(), std::sqrt(0.5), 1e-6);
}

TEST(TumRejects, EachRuleNamesFileAndLine) {
  expect_input_error([] { parse_tum("1 2 3 4 5 6 7\n", "a.tum"); }, {"a.tum", "line 1", "expected 8 values"});
  expect_input_error([] { parse_tum("#\n1 2 3 inf 0 0 0 1\n", "a.tum"); }, {"a.tum", "line 2", "finite"});
  expect_input_error([] { parse_tum("1 0 0 0 0 0 0 1.01\n", "a.tum"); }, {"a.tum", "line 1", "norm", "1e-3"});
  expect_input_error([] { parse_tum("1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", "a.tum"); }, {"a.tum", "line 2", "not after"});
  expect_input_error([] { parse_tum("1 0 0 0 0 0 0 x\n", "a.tum"); }, {"a.tum", "line 1", "'x'"});
}

TEST(KittiPosesRejects, EachRuleNamesFileAndLine) {
  expect_input_error([] { parse_kitti_poses("1 0 0 0 0 1 0 0 0 0 1\n", "p.txt"); }, {"p.txt", "line 1", "expected 12 values"});
  expect_input_error([] { parse_kitti_poses("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1.01 0 0 0 0 1 0\n", "p.txt"); },
                     {"p.txt", "line 2", "not a rotation"});
  expect_input_error([] { parse_kitti_poses("-1 0 0 0 0 1 0 0 0 0 1 0\n", "p.txt"); }, {"p.txt", "line 1", "det"});
  expect_input_error([] { parse_kitti_poses("1 0 0 0 0 1 0 0 0 0 1 0\n", "p.txt", {1.0, 2.0}); }, {"p.txt", "1 poses but 2 stamps"});
  expect_input_error(
      [] {
        parse_kitti_poses("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n", "p.txt", {2.0, 1.0});
      },
      {"p.txt", "line 2", "not after"});
}

TEST(KittiPosesReader, ReorthonormalisesPrintedRotations) {
  // A 30 degree yaw printed with 6 digits.
  const Trajectory t = parse_kitti_poses("0.866025 -0.5 0 1 0.5 0.866025 0 2 0 0 1 3\n", "p.txt");
  const Mat3 r = t.poses[0].T_world_base.rotation_matrix();
  EXPECT_LT((r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_NEAR(std::atan2(r(1, 0), r(0, 0)), M_PI / 6, 1e-6);
}

TEST(PoseFilesRealData, ScanPairReferencesAgree) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const auto folder = test::shared_data() / "real/scan_pair";
  const SE3 a = read_matrix_transform(folder / "T_target_source.txt");
  const SE3 b = read_matrix_transform(folder / "relative.txt");
  EXPECT_LT(rotation_error_rad(a, b), 0.5 * M_PI / 180.0);
  EXPECT_LT((a.translation() - b.translation()).norm(), 0.05);
  EXPECT_NEAR(a.translation().x(), 0.488882, 1e-9);  // as printed in the file
}

TEST(PoseFilesRealData, BalmPosesAreFiftyHalfSecondKeyframes) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const Trajectory t = read_balm_poses(test::shared_data() / "real/balm_ouster/alidarPose_0-49.csv");
  ASSERT_EQ(t.size(), 50u);
  EXPECT_DOUBLE_EQ(t.poses[0].stamp, 1630577758.569490);
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double dt = t.poses[i].stamp - t.poses[i - 1].stamp;
    EXPECT_GT(dt, 0.45) << i;  // keyframes 0.5 s apart (README), not 0.1 s sweeps
    EXPECT_LT(dt, 0.55) << i;
  }
  EXPECT_NEAR(t.poses[0].T_world_base.translation().x(), -0.005801, 1e-9);
}

TEST(PoseFilesRejects, BalmAndMatrixFiles) {
  expect_input_error([] { parse_balm_poses("1,0,0,0,\n0,1,0,0,\n0,0,1,0,\n", "b.csv"); }, {"b.csv", "not a multiple of 4"});
  expect_input_error([] { parse_balm_poses("1,0,0,0,\n0,1,0,0,\n0,0,1,0,\n0,0.5,0,10,\n", "b.csv"); }, {"b.csv", "line 1-4", "bottom row"});
  expect_input_error([] { parse_balm_poses("1,0,0,0,\n0,1,0,0,\n0,0,1,0,\n0,0,0,10,\n1,0,0,0,\n0,1,0,0,\n0,0,1,0,\n0,0,0,9,\n", "b.csv"); },
                     {"b.csv", "line 5-8", "not after"});
  expect_input_error([] { parse_matrix_transform("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0", "m.txt"); }, {"m.txt", "found 15"});
  expect_input_error([] { parse_matrix_transform("2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", "m.txt"); }, {"m.txt", "not a rotation"});
}

}  // namespace
}  // namespace mlidar::io
