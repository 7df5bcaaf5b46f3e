// Is the pairwise refinement's covariance honest? Over seeded simulated pairs
// (street scenes of different seeds, independent sensor noise; the truth is
// the oracle) the normalized estimation error squared
//   NEES = e^T C^-1 e,  e = [t_est - t_true, Log(R_est R_true^T)]
// of a consistent 6-dof estimator is chi-square with 6 dof, so the sum over N
// pairs is chi-square with 6N dof: its two-sided 99% bounds are the check.
#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/calib/pair_refine.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/lidar_models.hpp"
#include "mlidar/sim/scenes.hpp"

namespace mlidar::test {
namespace {

constexpr int kPairs = 10;
constexpr std::uint64_t kFirstSeed = 31;  // seeds 1-30 set the systematic term below
// chi-square(60) quantiles 0.005 and 0.995 (tables): the sum of 10 NEES.
constexpr double kChi2Low = 35.53;
constexpr double kChi2High = 91.95;

struct Nees {
  double reported = 0.0;  ///< with PairRefineResult::covariance
  double icp = 0.0;       ///< with covariance_icp alone
};

double nees(const Vec6& error, const Mat6& covariance) { return error.dot(covariance.ldlt().solve(error)); }

/// The rig of test_pair_refine_sim (HDL-64E reference, HDL-32E rolled 25 deg
/// and yawed 70 deg), standing in a street built from `seed`.
Nees nees_of_pair(std::uint64_t seed) {
  const SE3 T_ref_target(quat_from_rpy_deg(Vec3(25.0, -5.0, 70.0)), Vec3(0.4, 0.9, -0.5));
  const sim::SimLidar ref{"ref", sim::lidar_model("HDL-64E"), SE3(), 0.0, 0.0};
  const sim::SimLidar target{"target", sim::lidar_model("HDL-32E"), T_ref_target, 0.0, 0.0};
  const auto trajectory = sim::SimTrajectory::stationary(SE3(Quat::Identity(), Vec3(0.0, 0.0, 1.9)));
  const std::vector<Vec3> path{Vec3(-5, 0, 1.9), Vec3(0, 0, 1.9), Vec3(5, 0, 1.9)};
  const sim::Scene scene = sim::make_scene("street", seed, path);
  const auto ref_scan = sim::simulate_sweep(scene, ref, trajectory, 0.0, 2 * seed + 1).scan.points;
  const auto target_scan = sim::simulate_sweep(scene, target, trajectory, 0.0, 2 * seed + 2).scan.points;
  const SE3 T_init = SE3(so3_exp(Vec3(0.02, -0.01, 0.015)), Vec3(0.05, -0.05, 0.03)) * T_ref_target;
  calib::PairRefineConfig config;
  config.search_mode = calib::PairSearchMode::kNever;
  config.systematic_rotation_sd_deg = 0.002;  // simulated scans: synchronous, no motion; see the header
  config.systematic_translation_sd_m = 0.0006;
  const calib::PairRefineResult r = calib::refine_pair(ref_scan, target_scan, T_init, config);
  EXPECT_EQ(r.verdict, calib::PairVerdict::kConverged) << seed;
  Vec6 error;
  error << r.T_ref_target.translation() - T_ref_target.translation(),
      so3_log(r.T_ref_target.rotation() * T_ref_target.rotation().inverse());
  return {nees(error, r.covariance), nees(error, r.covariance_icp)};
}

TEST(PairRefineNees, ReportedCovarianceIsConsistentOverSeededPairs) {
  double sum = 0.0, sum_icp = 0.0;
  for (std::uint64_t seed = kFirstSeed; seed < kFirstSeed + kPairs; ++seed) {
    const Nees n = nees_of_pair(seed);
    std::cout << "seed " << seed << " NEES reported " << n.reported << ", ICP alone " << n.icp << '\n';
    sum += n.reported;
    sum_icp += n.icp;
  }
  std::cout << "mean NEES over " << kPairs << " pairs: reported " << sum / kPairs << ", ICP alone " << sum_icp / kPairs
            << " (consistent: 6)\n";
  EXPECT_GT(sum, kChi2Low);       // not over-cautious
  EXPECT_LT(sum, kChi2High);      // not over-confident
  EXPECT_GT(sum_icp, kChi2High);  // the ICP's own covariance alone is over-confident (why the term exists)
}

}  // namespace
}  // namespace mlidar::test
