// BaseFrame: results from the reference LiDAR's frame into a base frame that
// is no LiDAR, against direct composition and a Monte-Carlo of the covariance.
#include <random>

#include <gtest/gtest.h>

#include "mlidar/core/conversions.hpp"
#include "mlidar/pipelines/base_frame.hpp"
#include "pose_error.hpp"

namespace mlidar::test {
namespace {

pipelines::BaseFrame vehicle_frame() {
  // Lyft's roof LiDAR in the vehicle frame, rolled a little so that every axis mixes.
  return {"vehicle", 0, SE3(quat_from_rpy_deg(Vec3(3.0, -2.0, 30.0)), Vec3(1.197, 0.0, 1.828)), false};
}

TEST(BaseFrame, ExtrinsicsPosesAndPointsComposeWithTheReferencePlacement) {
  const pipelines::BaseFrame frame = vehicle_frame();
  const SE3 T_R_j(quat_from_rpy_deg(Vec3(0.0, 5.0, 45.0)), Vec3(2.3, 0.9, -1.3));
  const SE3 T_B_j = frame.extrinsic_to_base(T_R_j);
  // A point seen by LiDAR j lands where the reference's extrinsic puts it: p_B = T_B_R (T_R_j p).
  const Vec3 p(4.0, -1.0, 0.5);
  EXPECT_LT((T_B_j * p - frame.T_base_reference * (T_R_j * p)).norm(), 1e-12);
  EXPECT_LT(translation_error_m(frame.extrinsic_to_reference(T_B_j), T_R_j), 1e-12);
  EXPECT_LT(rotation_error_deg(frame.extrinsic_to_reference(T_B_j), T_R_j), 1e-10);
  // The base frame's trajectory starts at the identity when the reference's does, and moves the base origin.
  EXPECT_LT(frame.pose_to_base(SE3::identity()).log().norm(), 1e-12);
  const SE3 T_w_R(quat_from_rpy_deg(Vec3(0.0, 0.0, 10.0)), Vec3(5.0, 1.0, 0.0));
  const SE3 T_w_B = frame.pose_to_base(T_w_R);
  const Vec3 origin_R = frame.T_base_reference.inverse() * Vec3(Vec3::Zero());  // the base origin in R's frame
  EXPECT_LT((T_w_B.translation() - frame.T_base_reference * (T_w_R * origin_R)).norm(), 1e-12);
  const Eigen::Vector3f q(1.0F, 2.0F, 3.0F);
  EXPECT_LT((frame.point_to_base(q).cast<double>() - frame.T_base_reference * Vec3(q.cast<double>())).norm(), 1e-6);
}

TEST(BaseFrame, CovarianceMatchesAMonteCarloOfTheComposition) {
  const pipelines::BaseFrame frame = vehicle_frame();
  const SE3 T_R_j(quat_from_rpy_deg(Vec3(0.0, 5.0, 45.0)), Vec3(2.3, 0.9, -1.3));
  Mat6 sigma = Mat6::Zero();  // [t additive, r local], correlated
  sigma.diagonal() << 4e-4, 1e-4, 9e-4, 1e-5, 4e-5, 2e-5;
  sigma(0, 5) = sigma(5, 0) = 5e-5;
  const Mat6 expected = frame.covariance_to_base(sigma);
  const Eigen::LLT<Mat6> llt(sigma);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  const SE3 T_B_j = frame.extrinsic_to_base(T_R_j);
  Mat6 sampled = Mat6::Zero();
  constexpr int kSamples = 100000;
  for (int i = 0; i < kSamples; ++i) {
    Vec6 z;
    for (int a = 0; a < 6; ++a) z(a) = normal(rng);
    const Vec6 d = llt.matrixL() * z;
    const SE3 T(T_R_j.rotation() * so3_exp(d.tail<3>()), T_R_j.translation() + d.head<3>());
    const SE3 moved = frame.extrinsic_to_base(T);
    Vec6 e;
    e << moved.translation() - T_B_j.translation(), so3_log(T_B_j.rotation().conjugate() * moved.rotation());
    sampled += e * e.transpose() / kSamples;
  }
  for (int a = 0; a < 6; ++a) EXPECT_NEAR(sampled(a, a), expected(a, a), 0.02 * expected(a, a)) << a;
  EXPECT_NEAR(sampled(0, 1), expected(0, 1), 0.05 * std::sqrt(expected(0, 0) * expected(1, 1)));
}

}  // namespace
}  // namespace mlidar::test
