// SO(3) and SE(3) left/right Jacobians against central numeric differences,
// and their closed-form inverses, across the series/closed-form switch.
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "lie_test_util.hpp"
#include "mlidar/core/se3.hpp"

namespace mlidar {
namespace {

using test::numeric_jacobian;
using test::random_unit_vector;


// Angles that exercise zero, the Taylor branches (< 1e-2), both sides of the
// switch, ordinary angles and the neighbourhood of pi.
const std::vector<double> kAngles = {0.0, 1e-12, 1e-8, 1e-5, 1e-3, 0.0099, 0.0101, 0.3, 1.0, 2.0, 3.0, std::numbers::pi - 1e-6};

// J_l: Log(Exp(phi + d) Exp(phi)^-1) ~= J_l d;  J_r: Log(Exp(phi)^-1 Exp(phi + d)) ~= J_r d.
Mat3 numeric_so3_left(const Vec3& phi) {
  const Quat inv = so3_exp(phi).conjugate();
  return numeric_jacobian<3, 3>([&](const Vec3& d) { return so3_log(so3_exp(phi + d) * inv); }, Vec3::Zero());
}
Mat3 numeric_so3_right(const Vec3& phi) {
  const Quat inv = so3_exp(phi).conjugate();
  return numeric_jacobian<3, 3>([&](const Vec3& d) { return so3_log(inv * so3_exp(phi + d)); }, Vec3::Zero());
}
Mat6 numeric_se3_left(const Vec6& xi) {
  const SE3 inv = SE3::exp(xi).inverse();
  return numeric_jacobian<6, 6>([&](const Vec6& d) { return (SE3::exp(xi + d) * inv).log(); }, Vec6::Zero());
}
Mat6 numeric_se3_right(const Vec6& xi) {
  const SE3 inv = SE3::exp(xi).inverse();
  return numeric_jacobian<6, 6>([&](const Vec6& d) { return (inv * SE3::exp(xi + d)).log(); }, Vec6::Zero());
}

TEST(SO3Jacobian, LeftAndRightMatchNumericDifferences) {
  std::mt19937 rng(21);
  for (const double angle : kAngles) {
    for (int i = 0; i < 10; ++i) {
      const Vec3 phi = angle * random_unit_vector(rng);
      EXPECT_LT((so3_left_jacobian(phi) - numeric_so3_left(phi)).norm(), 1e-8) << "angle " << angle;
      EXPECT_LT((so3_right_jacobian(phi) - numeric_so3_right(phi)).norm(), 1e-8) << "angle " << angle;
    }
  }
}

TEST(SO3Jacobian, InversesAreInverses) {
  std::mt19937 rng(22);
  for (const double angle : kAngles) {
    for (int i = 0; i < 10; ++i) {
      const Vec3 phi = angle * random_unit_vector(rng);
      EXPECT_LT((so3_left_jacobian(phi) * so3_left_jacobian_inverse(phi) - Mat3::Identity()).norm(), 1e-13) << "angle " << angle;
      EXPECT_LT((so3_right_jacobian(phi) * so3_right_jacobian_inverse(phi) - Mat3::Identity()).norm(), 1e-13) << "angle " << angle;
    }
  }
}

// Identities independent of any derivative: J_l(phi) = R J_r(phi) and J_l(phi) phi = phi.
TEST(SO3Jacobian, LeftRightRelation) {
  std::mt19937 rng(23);
  for (const double angle : kAngles) {
    const Vec3 phi = angle * random_unit_vector(rng);
    const Mat3 r = so3_exp(phi).toRotationMatrix();
    EXPECT_LT((so3_left_jacobian(phi) - r * so3_right_jacobian(phi)).norm(), 1e-14) << "angle " << angle;
    EXPECT_LT((so3_left_jacobian(phi) * phi - phi).norm(), 1e-14) << "angle " << angle;
  }
}

TEST(SE3Jacobian, LeftAndRightMatchNumericDifferences) {
  std::mt19937 rng(24);
  std::uniform_real_distribution<double> unit(-3.0, 3.0);
  for (const double angle : kAngles) {
    for (int i = 0; i < 10; ++i) {
      Vec6 xi;
      xi << unit(rng), unit(rng), unit(rng), angle * random_unit_vector(rng);
      EXPECT_LT((se3_left_jacobian(xi) - numeric_se3_left(xi)).norm(), 1e-7) << "xi " << xi.transpose();
      EXPECT_LT((se3_right_jacobian(xi) - numeric_se3_right(xi)).norm(), 1e-7) << "xi " << xi.transpose();
    }
  }
}

TEST(SE3Jacobian, InversesAreInverses) {
  std::mt19937 rng(25);
  std::uniform_real_distribution<double> unit(-3.0, 3.0);
  for (const double angle : kAngles) {
    for (int i = 0; i < 10; ++i) {
      Vec6 xi;
      xi << unit(rng), unit(rng), unit(rng), angle * random_unit_vector(rng);
      EXPECT_LT((se3_left_jacobian(xi) * se3_left_jacobian_inverse(xi) - Mat6::Identity()).norm(), 1e-12) << "xi " << xi.transpose();
      EXPECT_LT((se3_right_jacobian(xi) * se3_right_jacobian_inverse(xi) - Mat6::Identity()).norm(), 1e-12) << "xi " << xi.transpose();
    }
  }
}

// Barfoot eq 7.88: J_l(xi) = Ad(exp(xi)) J_r(xi), and J_l(xi) xi = xi.
TEST(SE3Jacobian, LeftRightRelation) {
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> unit(-3.0, 3.0);
  for (const double angle : kAngles) {
    Vec6 xi;
    xi << unit(rng), unit(rng), unit(rng), angle * random_unit_vector(rng);
    EXPECT_LT((se3_left_jacobian(xi) - SE3::exp(xi).adjoint() * se3_right_jacobian(xi)).norm(), 1e-12) << "angle " << angle;
    EXPECT_LT((se3_left_jacobian(xi) * xi - xi).norm(), 1e-12) << "angle " << angle;
  }
}

}  // namespace
}  // namespace mlidar
