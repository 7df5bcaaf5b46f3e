#include <random>

#include <gtest/gtest.h>

#include "mlidar/core/se3.hpp"

namespace mlidar {
namespace {

Vec6 random_twist(std::mt19937& rng, double max_angle) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Vec3 axis(unit(rng), unit(rng), unit(rng));
  axis.normalize();
  std::uniform_real_distribution<double> angle(0.0, max_angle);
  Vec6 xi;
  xi << 5.0 * unit(rng), 5.0 * unit(rng), 5.0 * unit(rng), angle(rng) * axis;
  return xi;
}

TEST(SE3, ExpLogRoundTrip) {
  std::mt19937 rng(7);
  for (int i = 0; i < 1000; ++i) {
    const Vec6 xi = random_twist(rng, 3.1);
    EXPECT_LT((SE3::exp(xi).log() - xi).norm(), 1e-9) << xi.transpose();
  }
}

TEST(SE3, InverseComposesToIdentity) {
  std::mt19937 rng(11);
  for (int i = 0; i < 100; ++i) {
    const SE3 T = SE3::exp(random_twist(rng, 3.0));
    EXPECT_LT((T * T.inverse()).log().norm(), 1e-12);
  }
}

}  // namespace
}  // namespace mlidar
