// Timestamp association and trajectory validation.
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "eval_test_support.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/eval/association.hpp"
#include "mlidar/eval/trajectory_metrics.hpp"

namespace mlidar::eval {
namespace {

using test::wavy_trajectory;

std::string input_error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

TEST(Association, JitteredStampsPairWithTheirTwins) {
  const Trajectory gt = wavy_trajectory(200, 50.0);
  Trajectory est;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (i % 7 == 3) continue;  // the estimator dropped some frames
    est.poses.push_back({gt.poses[i].stamp + jitter(rng), gt.poses[i].T_world_base});
    kept.push_back(i);
  }
  const Association association = associate_by_time(gt, est, 0.01, "est");
  ASSERT_EQ(association.size(), kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k) {
    EXPECT_EQ(association.gt[k], kept[k]);
    EXPECT_EQ(association.est[k], k);
  }
  // With a tolerance smaller than the jitter only the close ones survive, still correctly paired.
  const Association tight = associate_by_time(gt, est, 0.002, "est");
  EXPECT_LT(tight.size(), kept.size());
  for (std::size_t k = 0; k < tight.size(); ++k) EXPECT_NEAR(gt.poses[tight.gt[k]].stamp, est.poses[tight.est[k]].stamp, 0.002);
}

TEST(Association, PairsAreOneToOne) {
  Trajectory gt;
  Trajectory est;
  for (int i = 0; i < 5; ++i) gt.poses.push_back({1.0 * i, SE3()});
  // Two estimates near gt stamp 2.0: only the closer one (2.001) is kept.
  for (const double t : {0.0, 1.0, 1.995, 2.001, 3.0, 4.0}) est.poses.push_back({t, SE3()});
  const Association association = associate_by_time(gt, est, 0.01, "est");
  ASSERT_EQ(association.size(), 5U);
  EXPECT_EQ(association.est[2], 3U);
}

TEST(Association, EmptyAssociationIsAnInputError) {
  const Trajectory gt = wavy_trajectory(20, 0.0);
  const Trajectory est = wavy_trajectory(20, 1000.0);  // another clock
  const std::string message = input_error_of([&] { associate_by_time(gt, est, 0.01, "est.tum"); });
  EXPECT_NE(message.find("est.tum"), std::string::npos) << message;
  EXPECT_NE(message.find("max_dt"), std::string::npos) << message;
}

TEST(Association, ByIndexNeedsEqualCounts) {
  const std::string message = input_error_of([] { associate_by_index(wavy_trajectory(10), wavy_trajectory(11), "est.kitti"); });
  EXPECT_NE(message.find("est.kitti"), std::string::npos) << message;
  EXPECT_EQ(associate_by_index(wavy_trajectory(10), wavy_trajectory(10), "e").size(), 10U);
}

TEST(Validation, BadTrajectoriesNameTheFileAndPose) {
  Trajectory nan_pose = wavy_trajectory(10);
  nan_pose.poses[4].T_world_base = SE3(Quat::Identity(), Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0));
  std::string message = input_error_of([&] { validate_trajectory(nan_pose, "a.tum"); });
  EXPECT_NE(message.find("a.tum"), std::string::npos) << message;
  EXPECT_NE(message.find("pose 4"), std::string::npos) << message;

  Trajectory nan_rotation = wavy_trajectory(10);
  nan_rotation.poses[2].T_world_base = SE3(Quat(std::numeric_limits<double>::quiet_NaN(), 0, 0, 0), Vec3::Zero());
  message = input_error_of([&] { validate_trajectory(nan_rotation, "a.tum"); });
  EXPECT_NE(message.find("pose 2"), std::string::npos) << message;

  Trajectory backwards = wavy_trajectory(10);
  backwards.poses[6].stamp = backwards.poses[5].stamp;
  message = input_error_of([&] { validate_trajectory(backwards, "b.tum"); });
  EXPECT_NE(message.find("pose 6"), std::string::npos) << message;
  EXPECT_NE(message.find("increase"), std::string::npos) << message;

  for (const std::size_t count : {0UL, 1UL}) {
    message = input_error_of([&] { validate_trajectory(wavy_trajectory(count), "c.tum"); });
    EXPECT_NE(message.find("at least 2"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(validate_trajectory(wavy_trajectory(2), "d.tum"));
}

TEST(Validation, EvaluateRejectsBadEstimate) {
  Trajectory est = wavy_trajectory(30);
  est.poses[3].stamp = 0.0;
  const std::string message =
      input_error_of([&] { evaluate_trajectory(wavy_trajectory(30), est, TrajectoryEvalOptions{}, "gt.tum", "est.tum"); });
  EXPECT_NE(message.find("est.tum"), std::string::npos) << message;
}

TEST(Validation, CoincidentPositionsCannotBeAligned) {
  Trajectory gt;
  for (int i = 0; i < 5; ++i) gt.poses.push_back({1.0 * i, SE3()});
  TrajectoryEvalOptions options;
  options.align = AlignMode::kSe3;
  EXPECT_THROW(evaluate_trajectory(gt, gt, options, "gt", "est"), InputError);
  options.align = AlignMode::kOrigin;
  EXPECT_NO_THROW(evaluate_trajectory(gt, gt, options, "gt", "est"));
}

}  // namespace
}  // namespace mlidar::eval
