// PS-Calib: exact recovery, invariance to the order and sign planes are found
// in, degenerate inputs, the verdict's warnings and the config checks.
#include <algorithm>
#include <array>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "corner_fixture.hpp"
#include "mlidar/calib/planes_calibrator.hpp"
#include "mlidar/calib/planes_refine.hpp"
#include "mlidar/core/error.hpp"
#include "pose_error.hpp"

namespace mlidar::test {
namespace {

using calib::PlanesCalibrator;
using calib::PlanesConfig;
using calib::PlanesWarning;

/// The three corner planes of the fixture in a LiDAR frame, unordered.
std::array<Plane, 3> world_planes_in(const SE3& T_world_lidar, double alpha) {
  const std::array<Plane, 3> world{Plane{Vec3(0, 1, 0), 0.0}, Plane{Vec3(std::sin(alpha), -std::cos(alpha), 0), 0.0},
                                   Plane{Vec3(0, 0, 1), 0.0}};
  std::array<Plane, 3> out;
  for (int i = 0; i < 3; ++i) {  // n_w.(R p + t) + d = (R^T n_w).p + n_w.t + d
    out[i] = {T_world_lidar.rotation().conjugate() * world[i].normal, world[i].normal.dot(T_world_lidar.translation()) + world[i].offset};
  }
  return out;
}

bool contains(const std::vector<PlanesWarning>& warnings, PlanesWarning w) {
  return std::find(warnings.begin(), warnings.end(), w) != warnings.end();
}

TEST(PlanesClosedForm, ExactPlanesGiveTheExactTransform) {
  for (const int configuration : {1, 2}) {
    const double alpha = 1.3;
    const SE3 T_world_ref = zyx_pose(alpha / 2 + 3.14159, 0, 0, Vec3(4 * std::cos(alpha / 2), 4 * std::sin(alpha / 2), 1.5));
    const SE3 truth = thesis_configuration(configuration);
    std::array<Plane, 3> ref = world_planes_in(T_world_ref, alpha);
    std::array<Plane, 3> target = world_planes_in(T_world_ref * truth, alpha);
    calib::orient_and_order(ref, Vec3::UnitZ());
    calib::orient_and_order(target, Vec3::UnitZ());
    const SE3 estimate = calib::closed_form_T_ref_target(ref, target);
    EXPECT_LT(rotation_error_rad(estimate, truth), 1e-9);
    EXPECT_LT(translation_error_m(estimate, truth), 1e-9);
  }
}

TEST(PlanesOrder, EveryPermutationAndSignGivesTheSameOrderedPlanes) {
  const double alpha = 1.7;
  const SE3 T_world_lidar = zyx_pose(2.0, 0.2, -0.1, Vec3(3, 2, 1.4));
  std::array<Plane, 3> reference = world_planes_in(T_world_lidar, alpha);
  calib::orient_and_order(reference, Vec3::UnitZ());
  std::array<int, 3> perm{0, 1, 2};
  int cases = 0;
  do {
    for (int signs = 0; signs < 8; ++signs) {
      std::array<Plane, 3> shuffled;
      for (int i = 0; i < 3; ++i) {
        shuffled[i] = reference[perm[i]];
        if ((signs >> i) & 1) shuffled[i] = shuffled[i].flipped();
      }
      calib::orient_and_order(shuffled, Vec3::UnitZ());
      for (int i = 0; i < 3; ++i) {
        EXPECT_LT((shuffled[i].normal - reference[i].normal).norm(), 1e-12);
        EXPECT_NEAR(shuffled[i].offset, reference[i].offset, 1e-12);
      }
      ++cases;
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  EXPECT_EQ(cases, 48);
  // eq 2.5 holds and eq 2.4's coefficients are positive (normals face the LiDAR: d > 0 here).
  EXPECT_GT(reference[1].normal.cross(reference[0].normal).dot(reference[2].normal), 0.0);
  for (const Plane& p : reference) EXPECT_GT(p.offset, 0.0);
}

TEST(PlanesRefine, NoiseFreePointsStayAtTheTruth) {
  const double alpha = 1.4;
  const SE3 truth = thesis_configuration(2);
  const SE3 T_world_ref = zyx_pose(alpha / 2 + 3.14159, 0, 0, Vec3(4 * std::cos(alpha / 2), 4 * std::sin(alpha / 2), 1.5));
  calib::RefineProblem problem;
  std::array<Plane, 3> planes = world_planes_in(T_world_ref, alpha);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int i = 0; i < 3; ++i) {  // double-precision points exactly on each plane, in both frames
    const Vec3 a = planes[i].normal.unitOrthogonal();
    const Vec3 b = planes[i].normal.cross(a);
    for (int k = 0; k < 200; ++k) {
      const Vec3 origin = -planes[i].offset * planes[i].normal;
      problem.ref_points[i].push_back(origin + u(rng) * a + u(rng) * b);
      problem.target_points[i].push_back(truth.inverse() * Vec3(origin + u(rng) * a + u(rng) * b));
    }
  }
  problem.planes_ref = planes;
  problem.T_ref_target = SE3(truth.rotation() * so3_exp(Vec3(0.02, -0.01, 0.03)), truth.translation() + Vec3(0.1, 0, -0.05));
  const calib::RefineResult result = calib::refine_planes(problem, {0.1, 100});
  EXPECT_TRUE(result.converged);
  EXPECT_LT(rotation_error_rad(result.T_ref_target, truth), 1e-9);
  EXPECT_LT(translation_error_m(result.T_ref_target, truth), 1e-9);
}

TEST(PlanesCalibrator, NoiseFreeCloudsRecoverTheTransformToFloatPrecision) {
  for (const int configuration : {1, 2}) {
    const CornerClouds clouds = make_corner(70.0, thesis_configuration(configuration), 3000, 0, 0.0, 11);
    const auto result = PlanesCalibrator(PlanesConfig{}).calibrate(clouds.ref, clouds.target, std::nullopt, "ref", "target");
    // Points are stored as float (7 significant digits over ~10 m), so 1e-5 is the floor here.
    EXPECT_LT(rotation_error_rad(result.T_ref_target, clouds.T_ref_target), 1e-5);
    EXPECT_LT(translation_error_m(result.T_ref_target, clouds.T_ref_target), 1e-5);
    EXPECT_TRUE(result.ok());
  }
}

TEST(PlanesCalibrator, ShuffledPointsGiveTheSameResult) {
  const CornerClouds clouds = make_corner(100.0, thesis_configuration(1), 3000, 600, 0.1, 21);
  const PlanesCalibrator calibrator{PlanesConfig{}};
  const auto first = calibrator.calibrate(clouds.ref, clouds.target, std::nullopt, "ref", "target");
  std::vector<Eigen::Vector3f> ref = clouds.ref;
  std::vector<Eigen::Vector3f> target = clouds.target;
  std::mt19937_64 rng(99);
  std::shuffle(ref.begin(), ref.end(), rng);
  std::shuffle(target.begin(), target.end(), rng);
  const auto second = calibrator.calibrate(target, ref, std::nullopt, "ref", "target");  // swapped roles too
  const SE3 back = second.T_ref_target.inverse();
  EXPECT_LT(rotation_error_rad(first.T_ref_target, back), 1e-3);
  EXPECT_LT(translation_error_m(first.T_ref_target, back), 1e-2);
  const auto third = calibrator.calibrate(ref, target, std::nullopt, "ref", "target");
  // Another RANSAC draw may keep a handful of different points at the band's
  // edge: the answers agree far inside their own standard deviation.
  const double sigma_r = std::sqrt(first.covariance.bottomRightCorner<3, 3>().trace());
  const double sigma_t = std::sqrt(first.covariance.topLeftCorner<3, 3>().trace());
  EXPECT_LT(rotation_error_rad(first.T_ref_target, third.T_ref_target), 0.1 * sigma_r);
  EXPECT_LT(translation_error_m(first.T_ref_target, third.T_ref_target), 0.1 * sigma_t);
}

TEST(PlanesCalibrator, GuessPicksTheMatchingWhenTheUpAxisIsWrong) {
  const CornerClouds clouds = make_corner(90.0, thesis_configuration(2), 3000, 300, 0.05, 31);
  PlanesConfig config;
  config.up = Vec3::UnitX();  // the floor heuristic now picks a wall
  const SE3 guess(clouds.T_ref_target.rotation() * so3_exp(Vec3(0.1, -0.1, 0.1)), Vec3::Zero());
  const auto result = PlanesCalibrator(config).calibrate(clouds.ref, clouds.target, guess, "ref", "target");
  EXPECT_LT(rotation_error_rad(result.T_ref_target, clouds.T_ref_target), 0.01);
  EXPECT_LT(translation_error_m(result.T_ref_target, clouds.T_ref_target), 0.02);
}

TEST(PlanesCalibrator, CloudsWithoutACornerAreRejectedByName) {
  const PlanesCalibrator calibrator{PlanesConfig{}};
  const CornerClouds good = make_corner(90.0, thesis_configuration(1), 3000, 300, 0.05, 41);
  const CornerClouds two = make_corner(90.0, thesis_configuration(1), 3000, 300, 0.05, 42, 2);
  std::vector<Eigen::Vector3f> parallel;  // three parallel planes z = 0, 2, 4
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(-5.F, 5.F);
  for (int i = 0; i < 3000; ++i) parallel.emplace_back(u(rng), u(rng), 2.0F * static_cast<float>(i % 3));
  const std::vector<Eigen::Vector3f> empty;
  for (const std::vector<Eigen::Vector3f>* bad : std::array<const std::vector<Eigen::Vector3f>*, 3>{&two.target, &parallel, &empty}) {
    try {
      calibrator.calibrate(good.ref, *bad, std::nullopt, "ref.pcd", "bad.pcd");
      ADD_FAILURE() << "accepted a cloud without a corner";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "bad.pcd");
      EXPECT_TRUE(e.field() == "planes" || e.field() == "points") << e.what();
    }
  }
}

TEST(PlanesCalibrator, ANarrowCornerWarnsThatPlanesAreNearlyParallel) {
  const CornerClouds clouds = make_corner(40.0, thesis_configuration(2), 3000, 0, 0.02, 51);
  const auto result = PlanesCalibrator(PlanesConfig{}).calibrate(clouds.ref, clouds.target, std::nullopt, "r", "t");
  EXPECT_TRUE(contains(result.warnings, PlanesWarning::kPlanesNearlyParallel));
  EXPECT_FALSE(result.ok());
  EXPECT_STREQ(calib::warning_name(PlanesWarning::kPlanesNearlyParallel), "planes_nearly_parallel");
}

TEST(PlanesCalibrator, SmallPlanesWarnFewInliers) {
  const CornerClouds clouds = make_corner(90.0, thesis_configuration(1), 600, 0, 0.02, 61);
  const auto result = PlanesCalibrator(PlanesConfig{}).calibrate(clouds.ref, clouds.target, std::nullopt, "r", "t");
  EXPECT_TRUE(contains(result.warnings, PlanesWarning::kFewInliers));
}

TEST(PlanesConfig, OutOfRangeValuesNameTheirKey) {
  PlanesConfig config;
  config.min_corner_angle_deg = 120.0;
  try {
    PlanesCalibrator calibrator(config);
    ADD_FAILURE() << "accepted min_corner_angle_deg = 120";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("min_corner_angle_deg"), std::string::npos);
  }
  config = PlanesConfig{};
  config.inlier_distance = -1.0;
  EXPECT_THROW(PlanesCalibrator{config}, UsageError);
}

}  // namespace
}  // namespace mlidar::test
