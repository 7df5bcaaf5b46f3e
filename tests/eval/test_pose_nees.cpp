// Pose NEES (eval/pose_nees.hpp) on constructed trajectories: errors chosen in
// the file's tangent give their NEES by hand, the start alignment removes a
// global offset, and errors drawn from the stated covariances fall inside the
// chi^2 band for about 95 % of the frames (below it when the covariance is 4x too large).
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "mlidar/core/error.hpp"
#include "mlidar/eval/pose_nees.hpp"

namespace mlidar::eval {
namespace {

SE3 ground_truth(int k) { return SE3(so3_exp(Vec3(0.01 * k, -0.02 * k, 0.1 * k)), Vec3(0.5 * k, 0.1 * k * k, 0.02 * k)); }

/// The estimate whose error against `truth` is e = [t_gt - t_est, Log(R_est^T R_gt)].
SE3 with_error(const SE3& truth, const Vec6& e) {
  const Quat R_est = truth.rotation() * so3_exp(e.tail<3>()).conjugate();  // R_gt = R_est Exp(r)
  return SE3(R_est, truth.translation() - e.head<3>());
}

struct Case {
  Trajectory gt, est;
  std::vector<io::StampedCovariance> covariances;
};

/// `frames` poses; frame 0 exact with zero covariance; later frames with error drawn from N(0, scale * C_k).
Case drawn_case(int frames, double scale, std::uint64_t seed, const SE3& est_world = SE3()) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Case c;
  for (int k = 0; k < frames; ++k) {
    const double stamp = 0.1 * k;
    Mat6 C = Mat6::Zero();
    Vec6 e = Vec6::Zero();
    if (k > 0) {
      const Mat6 A = Mat6::NullaryExpr([&] { return normal(rng); });
      C = (A * A.transpose() + Mat6::Identity()) * 1e-4 * k;
      const Vec6 z = Vec6::NullaryExpr([&] { return normal(rng); });
      e = std::sqrt(scale) * Mat6(C.llt().matrixL()) * z;
    }
    c.gt.poses.push_back({stamp, ground_truth(k)});
    c.est.poses.push_back({stamp, est_world * with_error(ground_truth(k), e)});
    c.covariances.push_back({stamp, C});
  }
  return c;
}

PoseNees nees_of(const Case& c) {
  const TrajectoryReport report = evaluate_trajectory(c.gt, c.est, {}, "gt", "est");
  std::vector<double> stamps;
  for (const auto& p : c.est.poses) stamps.push_back(p.stamp);
  return evaluate_pose_nees(report, c.covariances, "pose_covariance.txt", stamps);
}

TEST(PoseNees, AChosenErrorGivesItsNeesByHand) {
  Case c;
  const Vec6 e = (Vec6() << 0.02, -0.01, 0.03, 0.001, 0.002, -0.003).finished();
  const Vec6 sigma = (Vec6() << 0.01, 0.02, 0.03, 0.001, 0.001, 0.002).finished();
  for (int k = 0; k < 3; ++k) {
    c.gt.poses.push_back({0.1 * k, ground_truth(k)});
    c.est.poses.push_back({0.1 * k, k == 0 ? ground_truth(0) : with_error(ground_truth(k), e)});
    c.covariances.push_back({0.1 * k, k == 0 ? Mat6(Mat6::Zero()) : Mat6(sigma.cwiseProduct(sigma).asDiagonal())});
  }
  const PoseNees nees = nees_of(c);
  EXPECT_EQ(nees.skipped, 1u);  // the first frame: zero covariance
  ASSERT_EQ(nees.values.size(), 2u);
  const double expected = e.cwiseQuotient(sigma).squaredNorm();  // 4 + 0.25 + 1 + 1 + 4 + 2.25
  EXPECT_NEAR(nees.values[0], expected, 1e-6 * expected);
  EXPECT_NEAR(nees.translation.median, e.head<3>().cwiseQuotient(sigma.head<3>()).squaredNorm(), 1e-6);
  EXPECT_DOUBLE_EQ(nees.pose.inside, 1.0);
}

TEST(PoseNees, ConsistentCovariancesPutAbout95PercentInsideTheBand) {
  // The estimate in a world of its own (odometry starts at identity): the start alignment removes it.
  const SE3 elsewhere(so3_exp(Vec3(0.3, -0.2, 1.0)), Vec3(10.0, -4.0, 2.0));
  const PoseNees consistent = nees_of(drawn_case(2001, 1.0, 7, elsewhere));
  ASSERT_EQ(consistent.pose.frames, 2000u);
  EXPECT_NEAR(consistent.pose.inside, 0.95, 0.02);
  EXPECT_NEAR(consistent.translation.inside, 0.95, 0.02);
  EXPECT_NEAR(consistent.pose.median, 5.35, 0.4);                 // the chi^2(6) median
  const PoseNees too_large = nees_of(drawn_case(2001, 0.25, 7));  // errors half the stated sigma
  EXPECT_GT(too_large.pose.below, 0.4);
  const PoseNees too_small = nees_of(drawn_case(2001, 4.0, 7));
  EXPECT_GT(too_small.pose.above, 0.4);
}

TEST(PoseNees, NoMatchingCovarianceIsAnInputErrorNamingTheFile) {
  Case c = drawn_case(5, 1.0, 3);
  for (auto& cov : c.covariances) cov.stamp += 100.0;
  EXPECT_THROW(nees_of(c), InputError);
  try {
    nees_of(c);
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("pose_covariance.txt"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace mlidar::eval
