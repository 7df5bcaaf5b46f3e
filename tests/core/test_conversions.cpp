// Quaternion wxyz, rotation vector, roll-pitch-yaw and 4x4 matrix conversions.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "lie_test_util.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"

namespace mlidar {
namespace {

using test::rotation_error_rad;


TEST(Conversions, DegreesAndRadians) {
  EXPECT_DOUBLE_EQ(deg_to_rad(180.0), std::numbers::pi);
  EXPECT_DOUBLE_EQ(rad_to_deg(std::numbers::pi / 2.0), 90.0);
  EXPECT_DOUBLE_EQ(rad_to_deg(deg_to_rad(37.5)), 37.5);
}

TEST(Conversions, WxyzRoundTripAndSign) {
  std::mt19937 rng(51);
  for (int i = 0; i < 200; ++i) {
    const Quat q = so3_exp(test::random_rotation_vector(rng, 0.0, std::numbers::pi));
    const Vec4 wxyz = quat_to_wxyz(q);
    EXPECT_GE(wxyz(0), 0.0);
    EXPECT_NEAR(wxyz.norm(), 1.0, 1e-15);
    EXPECT_LT(rotation_error_rad(quat_from_wxyz(wxyz), q), 1e-14);
    EXPECT_LT(rotation_error_rad(quat_from_wxyz(-3.0 * wxyz), q), 1e-14);  // scale and sign free
  }
  // Field order: w first. [0, 0, 0, 1] is a half turn about z.
  EXPECT_LT((quat_from_wxyz(Vec4(0, 0, 0, 1)) * Vec3::UnitX() - Vec3(-1, 0, 0)).norm(), 1e-15);
}

TEST(Conversions, WxyzRejectsNonRotations) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(quat_from_wxyz(Vec4::Zero()), InputError);
  EXPECT_THROW(quat_from_wxyz(Vec4(1, nan, 0, 0)), InputError);
  EXPECT_THROW(quat_from_wxyz(Vec4(std::numeric_limits<double>::infinity(), 0, 0, 0)), InputError);
}

TEST(Conversions, RotationVectorRoundTrip) {
  std::mt19937 rng(52);
  for (int i = 0; i < 200; ++i) {
    const Vec3 phi = test::random_rotation_vector(rng, 0.0, std::numbers::pi - 1e-6);
    EXPECT_LT((rotation_vector_from_quat(quat_from_rotation_vector(phi)) - phi).norm(), 1e-12);
  }
}

// Oracle: R = Rz(yaw) Ry(pitch) Rx(roll) composed from so3_exp, and single-axis cases.
TEST(Conversions, RpyFollowsTheThesisConvention) {
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  for (int i = 0; i < 200; ++i) {
    const Vec3 rpy(angle(rng), angle(rng) / 2.0, angle(rng));
    const Quat expected = so3_exp(rpy.z() * Vec3::UnitZ()) * so3_exp(rpy.y() * Vec3::UnitY()) * so3_exp(rpy.x() * Vec3::UnitX());
    EXPECT_LT(rotation_error_rad(quat_from_rpy(rpy), expected), 1e-14);
  }
  // yaw 90 deg takes x to y; pitch 90 deg takes x to -z; roll 90 deg takes y to z.
  EXPECT_LT((quat_from_rpy_deg(Vec3(0, 0, 90)) * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_LT((quat_from_rpy_deg(Vec3(0, 90, 0)) * Vec3::UnitX() + Vec3::UnitZ()).norm(), 1e-15);
  EXPECT_LT((quat_from_rpy_deg(Vec3(90, 0, 0)) * Vec3::UnitY() - Vec3::UnitZ()).norm(), 1e-15);
}

TEST(Conversions, RpyRoundTripAwayFromGimbalLock) {
  std::mt19937 rng(54);
  std::uniform_real_distribution<double> angle(-std::numbers::pi + 1e-9, std::numbers::pi - 1e-9);
  std::uniform_real_distribution<double> pitch(-std::numbers::pi / 2.0 + 1e-3, std::numbers::pi / 2.0 - 1e-3);
  for (int i = 0; i < 500; ++i) {
    const Vec3 rpy(angle(rng), pitch(rng), angle(rng));
    EXPECT_LT((rpy_from_quat(quat_from_rpy(rpy)) - rpy).norm(), 1e-10) << rpy.transpose();
    const Vec3 rpy_deg = rpy * (180.0 / std::numbers::pi);
    EXPECT_LT((rpy_deg_from_quat(quat_from_rpy_deg(rpy_deg)) - rpy_deg).norm(), 1e-8);
  }
}

// Near pitch = +-90 deg the split of roll and yaw is ill-conditioned, but the
// angles returned must still rebuild the same rotation, and pitch stays exact.
TEST(Conversions, RpyNearGimbalLockRebuildsTheRotation) {
  std::mt19937 rng(55);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  for (const double side : {1.0, -1.0}) {
    for (const double gap : {1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13, 0.0}) {
      for (int i = 0; i < 20; ++i) {
        const Vec3 rpy(angle(rng), side * (std::numbers::pi / 2.0 - gap), angle(rng));
        const Quat q = quat_from_rpy(rpy);
        const Vec3 back = rpy_from_quat(q);
        EXPECT_LT(rotation_error_rad(quat_from_rpy(back), q), 1e-13) << "gap " << gap;
        EXPECT_NEAR(back.y(), rpy.y(), 1e-13) << "gap " << gap;
        EXPECT_LE(std::abs(back.y()), std::numbers::pi / 2.0);
        if (gap >= 1e-3) {
          EXPECT_LT((back - rpy).norm(), 1e-11) << "gap " << gap;
        }
      }
    }
  }
  // Exactly at the lock roll is 0 and yaw carries the whole angle.
  const Vec3 locked = rpy_from_quat(quat_from_rpy(Vec3(0.4, std::numbers::pi / 2.0, 0.1)));
  EXPECT_EQ(locked.x(), 0.0);
  EXPECT_NEAR(locked.z(), 0.1 - 0.4, 1e-14);
}

TEST(Conversions, MatrixRoundTrip) {
  std::mt19937 rng(56);
  for (int i = 0; i < 100; ++i) {
    const SE3 pose = test::random_pose(rng);
    const Mat4 m = se3_to_matrix(pose);
    EXPECT_EQ(m.row(3), Eigen::RowVector4d(0, 0, 0, 1));
    EXPECT_LT(test::pose_distance(se3_from_matrix(m), pose), 1e-14);
    EXPECT_LT((se3_to_matrix(se3_from_matrix(m)) - m).norm(), 1e-14);
  }
}

}  // namespace
}  // namespace mlidar
