// t_z from the ground planes (thesis 3.4.3.1) on synthetic scans of a known ground.
#include <random>

#include <gtest/gtest.h>

#include "mlidar/calib/ground_height.hpp"
#include "mlidar/core/so3.hpp"

namespace mlidar::calib {
namespace {

const SE3 kT_a_b(so3_exp(Vec3(0.05, -0.1, 2.0)), Vec3(-1.2, 0.5, -0.35));

/// Ground z = -1.8 in {a} (noisy), a wall x = 6, seen by a and by b = kT_a_b.
std::pair<Scan, Scan> ground_scans(std::uint64_t seed, double noise_m) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-12.0, 12.0);
  std::normal_distribution<double> n(0.0, noise_m);
  Scan a, b;
  for (int i = 0; i < 3000; ++i) {
    const Vec3 ground(u(rng), u(rng), -1.8 + n(rng));
    const Vec3 wall(6.0 + n(rng), u(rng), 0.1 * u(rng));
    for (const Vec3& p : {ground, wall}) {
      a.points.push_back(p.cast<float>());
      b.points.push_back((kT_a_b.inverse() * p).cast<float>());
    }
  }
  return {a, b};
}

TEST(GroundHeight, RecoversHeightAlongTheAxis) {
  const SE3 guess(kT_a_b.rotation(), kT_a_b.translation() + Vec3(0, 0, 0.35));  // planar hand-eye: t_z = 0
  std::vector<Scan> scans_a, scans_b;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    auto [a, b] = ground_scans(seed, 0.01);
    scans_a.push_back(std::move(a));
    scans_b.push_back(std::move(b));
  }
  const GroundHeightResult r = height_from_ground(scans_a, scans_b, guess, Vec3::UnitZ());
  EXPECT_EQ(r.frames_used, 5u);
  EXPECT_NEAR(r.T_a_b.translation().z(), kT_a_b.translation().z(), 0.005);
  EXPECT_NEAR(r.shift_m, -0.35, 0.005);
  EXPECT_DOUBLE_EQ(r.T_a_b.translation().x(), guess.translation().x());  // moves along the axis only
  EXPECT_LT(r.spread_m, 0.01);
}

TEST(GroundHeight, AxisSignDoesNotMatter) {
  const SE3 guess(kT_a_b.rotation(), kT_a_b.translation() + Vec3(0, 0, -0.2));
  auto [a, b] = ground_scans(3, 0.0);
  const auto up = ground_height_shift(a, b, guess, Vec3::UnitZ());
  const auto down = ground_height_shift(a, b, guess, -Vec3::UnitZ());
  ASSERT_TRUE(up && down);
  EXPECT_NEAR(*up, 0.2, 1e-4);
  EXPECT_NEAR(*down, -0.2, 1e-4);
}

TEST(GroundHeight, NoGroundGivesNoShift) {
  Scan a, b;
  for (int i = 0; i < 2000; ++i) {  // only a wall: no plane perpendicular to z
    a.points.emplace_back(5.0f, 0.01f * static_cast<float>(i % 100), 0.01f * static_cast<float>(i / 100));
  }
  b = a;
  EXPECT_FALSE(ground_height_shift(a, b, SE3::identity(), Vec3::UnitZ()).has_value());
  const std::vector<Scan> one{a};
  const GroundHeightResult r = height_from_ground(one, one, kT_a_b, Vec3::UnitZ());
  EXPECT_EQ(r.frames_used, 0u);
  EXPECT_TRUE(r.T_a_b.translation().isApprox(kT_a_b.translation()));
  EXPECT_THROW(height_from_ground(one, {}, kT_a_b, Vec3::UnitZ()), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::calib
