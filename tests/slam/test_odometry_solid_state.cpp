// Odometry on solid-state keyframes: a Livox-class scanner (no rings, no
// azimuth sweep, a 70 deg circular field of view, a non-repetitive rosette)
// gives 3.4k points per keyframe, keyframes taken at irregular gaps of 0.1-7 s
// (as a LiDAR-inertial SLAM keeps them) and already deskewed. Ray-cast in the
// simulator's campus along a handheld walk; the truth is the trajectory. No
// pair may be off (> 0.2 m or 2 deg) unless its later keyframe is flagged.
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/sim/scenes.hpp"
#include "mlidar/sim/trajectory.hpp"
#include "mlidar/slam/odometry.hpp"
#include "mlidar/slam/row_recovery.hpp"

namespace mlidar::slam {
namespace {

constexpr double kDegrees = std::numbers::pi / 180.0;

/// Rosette directions in the sensor frame (+x forward): off-axis angle
/// rho = half_fov |sin(a n)|, around the axis at angle b n (a / b irrational,
/// so the pattern does not repeat between keyframes: n runs on).
Eigen::Vector3d rosette_direction(std::uint64_t n, double half_fov_rad) {
  const double rho = half_fov_rad * std::abs(std::sin(0.0123456789 * static_cast<double>(n)));
  const double around = 0.0317 * std::numbers::sqrt2 * static_cast<double>(n);
  return {std::cos(rho), std::sin(rho) * std::cos(around), std::sin(rho) * std::sin(around)};
}

struct Keyframes {
  std::vector<Scan> scans;
  std::vector<SE3> truth;  ///< T_world_lidar at each keyframe
};

Keyframes solid_state_keyframes(std::uint64_t seed, int count, double max_gap_s) {
  const sim::SimTrajectory walk = sim::SimTrajectory::named("handheld", 1.5);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> gap(0.1, max_gap_s);
  std::vector<double> stamps{5.0};
  while (static_cast<int>(stamps.size()) < count) stamps.push_back(stamps.back() + gap(rng));
  std::vector<Vec3> path;
  for (double t = 0.0; t <= stamps.back() + 1.0; t += 0.5) path.push_back(walk.T_world_base(t).translation());
  const sim::Scene scene = sim::make_scene("campus", seed, path);
  // Looking forward, tilted 10 deg down, 20 cm above the base.
  const SE3 T_base_lidar(Quat(Eigen::AngleAxisd(10.0 * kDegrees, Vec3::UnitY())), Vec3(0.1, 0.0, 0.2));
  std::normal_distribution<double> noise(0.0, 0.02);
  Keyframes out;
  std::uint64_t n = seed * 1000003ULL;
  for (const double stamp : stamps) {
    const SE3 T_world_lidar = walk.T_world_base(stamp) * T_base_lidar;
    Scan scan;
    scan.stamp = stamp;
    while (scan.points.size() < 3400) {
      const Vec3 d = rosette_direction(n++, 35.2 * kDegrees);
      const auto hit = scene.cast({T_world_lidar.translation(), T_world_lidar.rotation() * d}, 0.0, 90.0, stamp);
      if (!hit || hit->t < 1.0) continue;
      scan.points.push_back(((hit->t + noise(rng)) * d).cast<float>());
    }
    out.scans.push_back(std::move(scan));
    out.truth.push_back(T_world_lidar);
  }
  return out;
}

struct Outcome {
  int pairs = 0, bad = 0, unflagged = 0, flagged = 0;
};

Outcome run(const Keyframes& keyframes, double bad_m, double bad_deg) {
  Odometry odometry({}, {{"livox", LidarModel{}, SE3::identity()}});
  std::vector<SE3> estimate;
  std::vector<bool> flagged;
  for (const Scan& scan : keyframes.scans) {
    const FrameResult result = odometry.process(Frame{scan.stamp, {scan}});
    EXPECT_EQ(result.lidar_row_source[0], RowSource::kVoxelFallback);
    estimate.push_back(result.T_world_base);
    flagged.push_back(result.flagged());
  }
  Outcome outcome;
  for (std::size_t k = 0; k + 1 < estimate.size(); ++k) {
    const SE3 error = (keyframes.truth[k].inverse() * keyframes.truth[k + 1]).inverse() * (estimate[k].inverse() * estimate[k + 1]);
    const double angle_deg = Eigen::AngleAxisd(error.rotation()).angle() / kDegrees;
    const bool bad = error.translation().norm() > bad_m || angle_deg > bad_deg;
    ++outcome.pairs;
    outcome.bad += bad ? 1 : 0;
    // A pair with a flagged pose at either end is flagged: a wrong pose flagged at k makes k -> k + 1 off as well.
    const bool pair_flagged = flagged[k] || flagged[k + 1];
    outcome.flagged += flagged[k + 1] ? 1 : 0;
    if (bad && !pair_flagged) {
      ++outcome.unflagged;
      std::cout << "  unflagged pair " << k << " (gap " << keyframes.scans[k + 1].stamp - keyframes.scans[k].stamp
                << " s): " << error.translation().norm() << " m " << angle_deg << " deg\n";
    }
  }
  return outcome;
}

TEST(OdometrySolidState, RosetteKeyframesShowNoRows) {
  const Keyframes keyframes = solid_state_keyframes(1, 3, 1.0);
  for (const Scan& scan : keyframes.scans) EXPECT_FALSE(recover_rows(scan.points).has_value());
}

TEST(OdometrySolidState, KeyframesCloseTogetherFollowTheTruth) {
  const Keyframes keyframes = solid_state_keyframes(1, 30, 0.3);
  const Outcome outcome = run(keyframes, 0.05, 1.0);
  std::cout << outcome.pairs << " pairs, " << outcome.bad << " off, " << outcome.flagged << " flagged\n";
  EXPECT_EQ(outcome.bad, 0);
}

TEST(OdometrySolidState, KeyframesUpToASecondApart) {
  for (const std::uint64_t seed : {1, 3}) {
    const Outcome outcome = run(solid_state_keyframes(seed, 20, 1.0), 0.2, 2.0);
    std::cout << "seed " << seed << ": " << outcome.pairs << " pairs, " << outcome.bad << " off, " << outcome.unflagged
              << " of them unflagged, " << outcome.flagged << " flagged\n";
    EXPECT_EQ(outcome.unflagged, 0) << "seed " << seed;
  }
}

TEST(OdometrySolidState, KeyframesAtIrregularGapsAreRightOrFlagged) {
  for (const std::uint64_t seed : {1, 2}) {
    const Keyframes keyframes = solid_state_keyframes(seed, 30, 7.0);
    const Outcome outcome = run(keyframes, 0.2, 2.0);
    std::cout << "seed " << seed << ": " << outcome.pairs << " pairs, " << outcome.bad << " off, " << outcome.unflagged
              << " of them unflagged, " << outcome.flagged << " flagged\n";
    EXPECT_EQ(outcome.unflagged, 0) << "seed " << seed;
  }
}

}  // namespace
}  // namespace mlidar::slam
