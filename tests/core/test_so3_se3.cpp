// Property tests of SO(3)/SE(3) exp/log, composition, adjoint and from_matrix.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "lie_test_util.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/core/se3.hpp"

namespace mlidar {
namespace {

using test::pose_distance;
using test::random_pose;
using test::random_twist;
using test::random_unit_vector;

constexpr double kPi = std::numbers::pi;

TEST(SO3, HatIsCrossProductAndVeeInvertsIt) {
  std::mt19937 rng(3);
  for (int i = 0; i < 100; ++i) {
    const Vec3 a = 3.0 * random_unit_vector(rng);
    const Vec3 b = random_unit_vector(rng);
    EXPECT_LT((hat(a) * b - a.cross(b)).norm(), 1e-15);
    EXPECT_EQ(vee(hat(a)), a);
  }
}

TEST(SO3, ExpMatchesAngleAxis) {
  std::mt19937 rng(5);
  for (int i = 0; i < 200; ++i) {
    const Vec3 phi = test::random_rotation_vector(rng, 0.0, kPi);
    const Mat3 expected = Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix();
    EXPECT_LT((so3_exp(phi).toRotationMatrix() - expected).norm(), 1e-14);
  }
}

TEST(SE3, ExpLogRoundTrip) {
  std::mt19937 rng(7);
  for (int i = 0; i < 1000; ++i) {
    const Vec6 xi = random_twist(rng, 0.0, 3.1);
    EXPECT_LT((SE3::exp(xi).log() - xi).norm(), 1e-9) << xi.transpose();
  }
}

TEST(SE3, LogExpRoundTripNearZeroAngle) {
  std::mt19937 rng(8);
  for (int i = 0; i < 1000; ++i) {
    const Vec6 xi = random_twist(rng, 1e-12, 1e-6, /*log_scale=*/true);
    const Vec6 back = SE3::exp(xi).log();
    // Rotation part relative to its (tiny) size, translation absolute.
    EXPECT_LT((back.tail<3>() - xi.tail<3>()).norm(), 1e-12 * xi.tail<3>().norm()) << xi.transpose();
    EXPECT_LT((back.head<3>() - xi.head<3>()).norm(), 1e-12) << xi.transpose();
  }
  EXPECT_EQ(SE3::exp(Vec6::Zero()).log(), Vec6::Zero());
}

TEST(SE3, LogExpRoundTripNearPi) {
  std::mt19937 rng(9);
  for (int i = 0; i < 1000; ++i) {
    const Vec6 xi = random_twist(rng, kPi - 1e-6, kPi);
    EXPECT_LT((SE3::exp(xi).log() - xi).norm(), 1e-9) << xi.transpose();
  }
}

// T from a raw quaternion whose w is tiny and of either sign (angle ~ pi), or
// whose vector part is tiny (angle ~ 0): exp(log T) must give T back.
TEST(SE3, ExpOfLogIsIdentityAtBothEnds) {
  std::mt19937 rng(10);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const double small : {0.0, 1e-15, 1e-12, 1e-9, 1e-7, 1e-6, 1e-4}) {
    for (int i = 0; i < 50; ++i) {
      const Vec3 axis = random_unit_vector(rng);
      const double sign = unit(rng) < 0.0 ? -1.0 : 1.0;
      const double big = std::sqrt(1.0 - small * small);
      const Vec3 t(5 * unit(rng), 5 * unit(rng), 5 * unit(rng));
      const SE3 near_pi(Quat(sign * small, big * axis.x(), big * axis.y(), big * axis.z()), t);
      const SE3 near_zero(Quat(sign * big, small * axis.x(), small * axis.y(), small * axis.z()), t);
      EXPECT_LT(pose_distance(SE3::exp(near_pi.log()), near_pi), 1e-12) << small;
      EXPECT_LT(pose_distance(SE3::exp(near_zero.log()), near_zero), 1e-12) << small;
      EXPECT_LE(near_pi.log().tail<3>().norm(), kPi + 1e-14);  // angle in [0, pi] up to rounding
    }
  }
}

TEST(SE3, InverseComposesToIdentity) {
  std::mt19937 rng(11);
  for (int i = 0; i < 100; ++i) {
    const SE3 T = SE3::exp(random_twist(rng, 0.0, 3.0));
    EXPECT_LT((T * T.inverse()).log().norm(), 1e-12);
    EXPECT_LT((T.inverse() * T).log().norm(), 1e-12);
  }
}

TEST(SE3, CompositionIsAssociativeAndMatchesMatrices) {
  std::mt19937 rng(12);
  for (int i = 0; i < 200; ++i) {
    const SE3 a = random_pose(rng);
    const SE3 b = random_pose(rng);
    const SE3 c = random_pose(rng);
    const Vec3 p = 10.0 * random_unit_vector(rng);
    EXPECT_LT(pose_distance((a * b) * c, a * (b * c)), 1e-12);
    EXPECT_LT(pose_distance((a * b).inverse(), b.inverse() * a.inverse()), 1e-12);
    EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-12);
    EXPECT_LT(((a * b).matrix() - a.matrix() * b.matrix()).norm(), 1e-12);
    const Eigen::Vector4d p_h = a.matrix() * p.homogeneous();
    EXPECT_LT((a * p - p_h.head<3>()).norm(), 1e-12);
  }
}

TEST(SE3, TransformPointsMatchesOperatorPerPoint) {
  std::mt19937 rng(17);
  const SE3 T = random_pose(rng);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 1000; ++i) points.push_back((50.0 * random_unit_vector(rng)).cast<float>());
  std::vector<Eigen::Vector3f> out(points.size());
  transform_points(T, points, out);
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_LT((out[i] - T * points[i]).norm(), 1e-5f);
  transform_points(T, points, points);  // in place
  EXPECT_EQ(points, out);
  std::vector<Eigen::Vector3f> too_short(points.size() - 1);
  EXPECT_THROW(transform_points(T, points, too_short), std::invalid_argument);
}

TEST(SE3, AdjointIdentity) {
  std::mt19937 rng(13);
  for (int i = 0; i < 500; ++i) {
    const SE3 T = random_pose(rng);
    const Vec6 xi = random_twist(rng, 0.0, 3.0);
    const SE3 lhs = T * SE3::exp(xi) * T.inverse();
    const SE3 rhs = SE3::exp(T.adjoint() * xi);
    EXPECT_LT(pose_distance(lhs, rhs), 1e-10);
  }
}

TEST(SE3, AdjointOfInverseAndProduct) {
  std::mt19937 rng(14);
  for (int i = 0; i < 100; ++i) {
    const SE3 a = random_pose(rng);
    const SE3 b = random_pose(rng);
    EXPECT_LT((a.inverse().adjoint() - a.adjoint().inverse()).norm(), 1e-10);
    EXPECT_LT(((a * b).adjoint() - a.adjoint() * b.adjoint()).norm(), 1e-10);
  }
}

TEST(SE3, FromMatrixRoundTrip) {
  std::mt19937 rng(15);
  for (int i = 0; i < 100; ++i) {
    const SE3 T = random_pose(rng);
    EXPECT_LT(pose_distance(SE3::from_matrix(T.matrix()), T), 1e-14);
  }
}

// Small drift (rounded text) is fixed: the result is the polar factor R of
// M = R S, i.e. R^T M is symmetric positive definite, and it is orthonormal.
TEST(SE3, FromMatrixProjectsSmallDriftToNearestRotation) {
  std::mt19937 rng(16);
  std::normal_distribution<double> noise(0.0, 1e-5);
  for (int i = 0; i < 100; ++i) {
    Mat4 m = random_pose(rng).matrix();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m(r, c) += noise(rng);
    }
    const SE3 fixed = SE3::from_matrix(m);
    const Mat3 r = fixed.rotation_matrix();
    EXPECT_LT((r.transpose() * r - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
    const Mat3 s = r.transpose() * m.topLeftCorner<3, 3>();
    EXPECT_LT((s - s.transpose()).norm(), 1e-12);
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat3>(s).eigenvalues().minCoeff(), 0.0);
    EXPECT_EQ(fixed.translation(), Vec3(m.topRightCorner<3, 1>()));
  }
}

TEST(SE3, FromMatrixRejectsNonRigidMatrices) {
  const Mat4 rotation = SE3(so3_exp(Vec3(0.3, -0.2, 1.0)), Vec3(1, 2, 3)).matrix();
  Mat4 scaled = rotation;
  scaled.topLeftCorner<3, 3>() *= 1.01;
  Mat4 sheared = rotation;
  sheared(0, 1) += 0.05;
  Mat4 reflected = rotation;
  reflected.col(2) *= -1.0;
  Mat4 bad_bottom = rotation;
  bad_bottom(3, 3) = 2.0;
  Mat4 with_nan = rotation;
  with_nan(1, 3) = std::numeric_limits<double>::quiet_NaN();
  for (const Mat4& m : {scaled, sheared, reflected, bad_bottom, with_nan}) {
    EXPECT_THROW(SE3::from_matrix(m), InputError) << m;
  }
  // A looser tolerance accepts the 1% scale and removes it.
  const SE3 fixed = SE3::from_matrix(scaled, 0.1);
  EXPECT_LT(pose_distance(fixed, SE3::from_matrix(rotation)), 1e-14);
  // Messages name the field and the problem.
  try {
    SE3::from_matrix(reflected);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "4x4 matrix");
    EXPECT_NE(std::string(e.what()).find("reflection"), std::string::npos);
  }
}

// A rotation SE3 has normalised is kept bit for bit when it is given again, so
// a pose written with every digit and read back is the same pose (normalising
// twice moved the last bit: found by fuzz_dataset).
TEST(SE3, NormalisingAgainKeepsTheBits) {
  std::size_t moved_by_normalising_twice = 0;
  for (int k = 0; k < 1000; ++k) {
    const double a = 0.001 * k;
    const Quat off_unit(1.0 + 1e-9 * std::sin(7.0 * a), std::sin(a), std::cos(3.0 * a), 0.5 * std::sin(5.0 * a));
    const Quat once = SE3(off_unit, Vec3::Zero()).rotation();
    EXPECT_NEAR(once.norm(), 1.0, 1e-15);
    EXPECT_EQ(SE3(once, Vec3::Zero()).rotation().coeffs(), once.coeffs()) << k;
    if (once.normalized().coeffs() != once.coeffs()) ++moved_by_normalising_twice;
  }
  EXPECT_GT(moved_by_normalising_twice, 0u);  // the case exists: plain normalized() is no fixpoint
}

}  // namespace
}  // namespace mlidar
