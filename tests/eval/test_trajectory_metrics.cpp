// ATE / RPE / KITTI metric against analytic answers and a hand-made case
// checked against evo's published definitions.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "eval_test_support.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/eval/trajectory_metrics.hpp"

namespace mlidar::eval {
namespace {

using test::poses_of;
using test::wavy_trajectory;

constexpr double kDeg = std::numbers::pi / 180.0;

/// Applies p -> s R p + t to every pose (rotation R R_i).
Trajectory transformed(const Trajectory& trajectory, const SE3& T, double scale = 1.0) {
  Trajectory out = trajectory;
  for (StampedPose& pose : out.poses) {
    pose.T_world_base =
        SE3(T.rotation() * pose.T_world_base.rotation(), scale * (T.rotation() * pose.T_world_base.translation()) + T.translation());
  }
  return out;
}

TrajectoryReport evaluate(const Trajectory& gt, const Trajectory& est, AlignMode align, double delta = 1.0,
                          DeltaUnit unit = DeltaUnit::kFrames) {
  TrajectoryEvalOptions options;
  options.align = align;
  options.delta = delta;
  options.delta_unit = unit;
  return evaluate_trajectory(gt, est, options, "gt.tum", "est.tum");
}

const SE3 kOffset(so3_exp(Vec3(0.3, -0.2, 1.1)), Vec3(4.0, -3.0, 2.0));

TEST(Ate, RigidlyMovedCopyVanishesAfterSe3AndOriginAlignment) {
  const Trajectory gt = wavy_trajectory(300);
  const Trajectory est = transformed(gt, kOffset);
  for (const AlignMode mode : {AlignMode::kSe3, AlignMode::kSim3, AlignMode::kOrigin}) {
    const TrajectoryReport report = evaluate(gt, est, mode);
    EXPECT_LT(report.ate.translation_m.max, 1e-9) << align_mode_name(mode);
    EXPECT_LT(report.ate.rotation_deg.max, 1e-6) << align_mode_name(mode);
    EXPECT_NEAR(report.alignment.scale, 1.0, 1e-12);
  }
}

TEST(Ate, WithoutAlignmentGivesTheOffsetError) {
  const Trajectory gt = wavy_trajectory(300);
  const Trajectory est = transformed(gt, kOffset);
  const TrajectoryReport report = evaluate(gt, est, AlignMode::kNone);
  double sum_sq = 0.0;
  for (const StampedPose& pose : gt.poses)
    sum_sq += (kOffset * pose.T_world_base.translation() - pose.T_world_base.translation()).squaredNorm();
  EXPECT_NEAR(report.ate.translation_m.rmse, std::sqrt(sum_sq / 300.0), 1e-9);
  // R_gt^T (R R_gt) is conjugate to R: the same angle for every pose.
  const double angle_deg = so3_log(kOffset.rotation()).norm() / kDeg;
  EXPECT_NEAR(report.ate.rotation_deg.rmse, angle_deg, 1e-9);
  EXPECT_NEAR(report.ate.rotation_deg.std, 0.0, 1e-9);
  // The offset multiplies from the left: every relative pose is unchanged.
  EXPECT_LT(report.rpe.translation_m.max, 1e-9);
  EXPECT_LT(report.rpe.rotation_deg.max, 1e-6);
}

TEST(Ate, ScaledCopyNeedsSim3) {
  const Trajectory gt = wavy_trajectory(300);
  const Trajectory est = transformed(gt, kOffset, 2.5);
  const TrajectoryReport sim3 = evaluate(gt, est, AlignMode::kSim3);
  EXPECT_LT(sim3.ate.translation_m.max, 1e-9);
  EXPECT_NEAR(sim3.alignment.scale, 1.0 / 2.5, 1e-12);
  EXPECT_LT(sim3.rpe.translation_m.max, 1e-9);  // RPE uses the aligned (rescaled) estimate
  const TrajectoryReport se3 = evaluate(gt, est, AlignMode::kSe3);
  EXPECT_GT(se3.ate.translation_m.rmse, 1.0);
}

TEST(Ate, ConstantTranslationOffsetGivesItsLength) {
  const Trajectory gt = wavy_trajectory(100);
  const Vec3 offset(0.3, 0.4, 0.0);  // |offset| = 0.5
  const TrajectoryReport report = evaluate(gt, transformed(gt, SE3(Quat::Identity(), offset)), AlignMode::kNone);
  EXPECT_NEAR(report.ate.translation_m.rmse, 0.5, 1e-12);
  EXPECT_NEAR(report.ate.translation_m.mean, 0.5, 1e-12);
  EXPECT_NEAR(report.ate.translation_m.median, 0.5, 1e-12);
  EXPECT_NEAR(report.ate.translation_m.std, 0.0, 1e-12);
  EXPECT_NEAR(report.ate.rotation_deg.max, 0.0, 1e-9);
}

TEST(Rpe, ConstantPerStepErrorIsRecovered) {
  // est_{i+1} = est_i (gt_i^-1 gt_{i+1}) E, so (gt_i^-1 gt_{i+1})^-1 (est_i^-1 est_{i+1}) = E for every step.
  const Trajectory gt = wavy_trajectory(200);
  const SE3 E(so3_exp(Vec3(0.0, 0.0, 0.5 * kDeg)), Vec3(0.02, 0.0, 0.0));
  Trajectory est = gt;
  for (std::size_t i = 1; i < gt.size(); ++i) {
    const SE3 step = gt.poses[i - 1].T_world_base.inverse() * gt.poses[i].T_world_base;
    est.poses[i].T_world_base = est.poses[i - 1].T_world_base * step * E;
  }
  const TrajectoryReport report = evaluate(gt, est, AlignMode::kNone);
  EXPECT_EQ(report.rpe.translation_m.count, 199U);
  EXPECT_NEAR(report.rpe.translation_m.rmse, 0.02, 1e-9);
  EXPECT_NEAR(report.rpe.translation_m.std, 0.0, 1e-9);
  EXPECT_NEAR(report.rpe.rotation_deg.mean, 0.5, 1e-7);
}

// Hand-made case, evo definitions (evo/core/metrics.py APE/RPE, filters.py):
//   gt : positions (0,0,0) (1,0,0) (2,0,0) (3,0,0), all rotations identity.
//   est: positions (0,0,0) (1,0.1,0) (2,0,0) (3,-0.1,0); est_3 yawed by 10 deg.
// APE translation (no alignment): errors 0, 0.1, 0, 0.1 ->
//   rmse = sqrt(0.02 / 4) = 0.0707107, mean = 0.05, median = (0 + 0.1)/2 = 0.05,
//   std (ddof 0) = 0.05, min 0, max 0.1. APE rotation: 0, 0, 0, 10 deg -> rmse = sqrt(100/4) = 5.
// RPE delta 1 frame, pairs (0,1) (1,2) (2,3): E = rel_gt^-1 rel_est =
//   (I, (0,0.1,0)), (I, (0,-0.1,0)), (Rz(10), (1,-0.1,0) - (1,0,0)) -> translation 0.1 each
//   (10 % of the 1 m step), rotation 0, 0, 10 -> rmse = sqrt(100/3) = 5.7735027, median 0.
// RPE delta 1 m (evo filter_pairs_by_path): path reaches 1 m at poses 1, 2, 3 -> pairs (1,2) (2,3):
//   rotation 0, 10 -> rmse = sqrt(50) = 7.0710678.
// RPE delta 2 m: only pose 2 reaches 2 m (the path restarts there) -> no pair at all.
TEST(EvoCrossCheck, HandMadeCase) {
  Trajectory gt;
  Trajectory est;
  const Vec3 est_positions[] = {{0, 0, 0}, {1, 0.1, 0}, {2, 0, 0}, {3, -0.1, 0}};
  for (int i = 0; i < 4; ++i) {
    gt.poses.push_back({0.1 * i, SE3(Quat::Identity(), Vec3(i, 0, 0))});
    const Quat rotation = i == 3 ? so3_exp(Vec3(0, 0, 10 * kDeg)) : Quat::Identity();
    est.poses.push_back({0.1 * i, SE3(rotation, est_positions[i])});
  }
  const TrajectoryReport report = evaluate(gt, est, AlignMode::kNone);
  EXPECT_NEAR(report.ate.translation_m.rmse, 0.0707106781, 1e-9);
  EXPECT_NEAR(report.ate.translation_m.mean, 0.05, 1e-12);
  EXPECT_NEAR(report.ate.translation_m.median, 0.05, 1e-12);
  EXPECT_NEAR(report.ate.translation_m.std, 0.05, 1e-12);
  EXPECT_NEAR(report.ate.translation_m.min, 0.0, 1e-12);
  EXPECT_NEAR(report.ate.translation_m.max, 0.1, 1e-12);
  EXPECT_NEAR(report.ate.rotation_deg.rmse, 5.0, 1e-9);

  EXPECT_EQ(report.rpe.translation_m.count, 3U);
  EXPECT_NEAR(report.rpe.translation_m.rmse, 0.1, 1e-12);
  EXPECT_NEAR(report.rpe.translation_m.std, 0.0, 1e-12);
  EXPECT_NEAR(report.rpe.translation_percent.mean, 10.0, 1e-9);
  EXPECT_NEAR(report.rpe.rotation_deg.rmse, 5.7735026919, 1e-8);
  EXPECT_NEAR(report.rpe.rotation_deg.median, 0.0, 1e-9);
  EXPECT_NEAR(report.rpe.rotation_deg.max, 10.0, 1e-9);

  const TrajectoryReport by_metre = evaluate(gt, est, AlignMode::kNone, 1.0, DeltaUnit::kMeters);
  EXPECT_EQ(by_metre.rpe.rotation_deg.count, 2U);
  EXPECT_NEAR(by_metre.rpe.rotation_deg.rmse, 7.0710678119, 1e-8);
  const TrajectoryReport two_metres = evaluate(gt, est, AlignMode::kNone, 2.0, DeltaUnit::kMeters);
  EXPECT_EQ(two_metres.rpe.translation_m.count, 0U);
  EXPECT_TRUE(std::isnan(two_metres.rpe.translation_m.rmse));
  EXPECT_FALSE(report.kitti.has_value());  // 3 m of path: no 100 m segment
}

TEST(KittiMetric, UniformScaleDriftOnAStraightLine) {
  // 1001 poses 1 m apart on the x axis; the estimate stretches every step by (1 + eps).
  // Devkit segment from `first` of length L ends at first + L + 1 (first frame with
  // dist > dist[first] + L), so its translation error is eps (L + 1) and t_err = eps (L + 1) / L.
  // Starting frames are multiples of 10 with first + L + 1 <= 1000.
  const double eps = 0.01;
  std::vector<SE3> gt;
  std::vector<SE3> est;
  for (int i = 0; i <= 1000; ++i) {
    gt.emplace_back(Quat::Identity(), Vec3(i, 0, 0));
    est.emplace_back(Quat::Identity(), Vec3((1.0 + eps) * i, 0, 0));
  }
  double expected_sum = 0.0;
  std::size_t expected_segments = 0;
  const auto kitti = compute_kitti_odometry(gt, est);
  ASSERT_TRUE(kitti.has_value());
  ASSERT_EQ(kitti->by_length.size(), 8u);
  for (int length = 100; length <= 800; length += 100) {
    const int starts = (1000 - length - 1) / 10 + 1;
    expected_segments += static_cast<std::size_t>(starts);
    expected_sum += starts * eps * (length + 1.0) / length;
    // Per length (the devkit's drift-against-length plot): every segment of length L drifts eps (L + 1) / L.
    const KittiLengthDrift& drift = kitti->by_length[static_cast<std::size_t>(length / 100 - 1)];
    EXPECT_EQ(drift.length_m, length);
    EXPECT_EQ(drift.segments, static_cast<std::size_t>(starts));
    EXPECT_NEAR(drift.translation_percent, 100.0 * eps * (length + 1.0) / length, 1e-9);
    EXPECT_NEAR(drift.rotation_deg_per_100m, 0.0, 1e-9);
  }
  EXPECT_EQ(kitti->segments, expected_segments);
  EXPECT_NEAR(kitti->translation_percent, 100.0 * expected_sum / static_cast<double>(expected_segments), 1e-9);
  EXPECT_NEAR(kitti->rotation_deg_per_100m, 0.0, 1e-9);
}

TEST(KittiMetric, ConstantYawRateErrorGivesItsDriftPerLengthOnlyWhereSegmentsFit) {
  // 351 poses 1 m apart on the x axis; the estimate turns 0.001 rad more about z per metre (its positions on the
  // same line): a segment of length L ends at first + L + 1 and its rotation error is 0.001 (L + 1) rad, so
  // r_err / L = 0.001 (L + 1) / L rad/m. Only 100-300 m segments fit in 350 m.
  std::vector<SE3> gt, est;
  for (int i = 0; i <= 350; ++i) {
    gt.emplace_back(Quat::Identity(), Vec3(i, 0, 0));
    est.emplace_back(Quat(Eigen::AngleAxisd(0.001 * i, Vec3::UnitZ())), Vec3(i, 0, 0));
  }
  const auto kitti = compute_kitti_odometry(gt, est);
  ASSERT_TRUE(kitti.has_value());
  ASSERT_EQ(kitti->by_length.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    const double length = 100.0 * static_cast<double>(k + 1);
    EXPECT_EQ(kitti->by_length[k].length_m, length);
    EXPECT_EQ(kitti->by_length[k].segments, static_cast<std::size_t>((350 - length - 1) / 10) + 1);
    EXPECT_NEAR(kitti->by_length[k].rotation_deg_per_100m, 100.0 * 0.001 * (length + 1.0) / length * 180.0 / std::numbers::pi, 1e-6);
  }
}

TEST(TrajectoryOptions, BadValuesAreUsageErrors) {
  const Trajectory gt = wavy_trajectory(10);
  EXPECT_THROW(evaluate(gt, gt, AlignMode::kSe3, 0.0), UsageError);
  EXPECT_THROW(evaluate(gt, gt, AlignMode::kSe3, 1.5), UsageError);  // frames must be whole
  EXPECT_NO_THROW(evaluate(gt, gt, AlignMode::kSe3, 1.5, DeltaUnit::kMeters));
}

}  // namespace
}  // namespace mlidar::eval
