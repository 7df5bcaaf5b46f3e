// The frames detectors read: a simulated dataset through its extrinsics, tr(Xi) per point, injected perturbation,
// augmentation of points and boxes alike.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/detect/box_coding.hpp"
#include "mlidar/detect/detection_frames.hpp"
#include "mlidar/detect/online_extrinsics.hpp"
#include "mlidar/sim/detection_dataset.hpp"
#include "mlidar/sim/rig.hpp"
#include "pose_error.hpp"
#include "test_support.hpp"

namespace mlidar::detect {
namespace {

namespace fs = std::filesystem;

fs::path lyft_dataset(int frames, sim::DetectionLayout layout) {
  const fs::path folder = test::scratch_dir() / "lyft";
  sim::DetectionSpec spec;
  spec.rig = sim::load_rig("lyft");
  spec.frames = frames;
  spec.seed = 3;
  spec.layout = layout;
  sim::write_detection_dataset(spec, folder);
  return folder;
}

fs::path cars_dataset(int frames) { return lyft_dataset(frames, sim::DetectionLayout::kCars); }

/// The eight corners of a box.
std::vector<Vec3> corners(const io::Box3D& box) {
  std::vector<Vec3> out;
  for (const double x : {-0.5, 0.5}) {
    for (const double y : {-0.5, 0.5}) {
      for (const double z : {-0.5, 0.5}) out.push_back(from_canonical(Vec3(x, y, z), box));
    }
  }
  return out;
}

TEST(DetectionFrames, PointsComeInTheBaseFrameAndSitOnTheirCars) {
  const fs::path folder = cars_dataset(2);
  const DetectionDataset dataset = DetectionDataset::open(folder, true);
  ASSERT_EQ(dataset.lidar_names(), (std::vector<std::string>{"top", "front_left", "front_right"}));
  EXPECT_EQ(dataset.dataset_alpha(), 0.0);
  const DetectionFrame frame = dataset.read(1);
  EXPECT_EQ(frame.id, "000001");
  ASSERT_FALSE(frame.labels.empty());
  // Every car is hit, and in the base frame its points lie in its labelled box (0.12 m of noise allowed).
  const LidarPoints all = merge_lidars(frame);
  for (const io::LabelledBox& label : frame.labels) {
    io::Box3D grown = label.box;
    grown.length += 0.3, grown.width += 0.3, grown.height += 0.3, grown.center_bottom.z() -= 0.15;
    int inside = 0;
    for (const Vec3& p : all.points) {
      const Vec3 c = to_canonical(p, grown);
      inside += c.cwiseAbs().maxCoeff() <= 0.5 ? 1 : 0;
    }
    EXPECT_GT(inside, 10) << "car at " << label.box.center_bottom.transpose();
  }
  // Clean extrinsics: every point's tr(Xi) is the prior's point noise alone, 3 (1/50)^2.
  for (const double u : all.uncertainty) ASSERT_NEAR(u, 3.0 / 2500.0, 1e-12);
}

TEST(DetectionFrames, InjectedPerturbationMovesTheOtherLidarsAndRaisesTheirUncertainty) {
  const fs::path folder = cars_dataset(1);
  const DetectionDataset dataset = DetectionDataset::open(folder, true);
  const DetectionFrame clean = dataset.read(0);
  const DetectionFrame perturbed = dataset.read(0, 0.04, 7);
  const DetectionFrame again = dataset.read(0, 0.04, 7);
  const DetectionFrame other = dataset.read(0, 0.04, 8);
  const std::size_t ref = dataset.reference();
  EXPECT_EQ(perturbed.lidars[ref].points, clean.lidars[ref].points);  // the reference defines the base: never perturbed
  for (std::size_t j = 0; j < clean.lidars.size(); ++j) {
    if (j == ref) continue;
    ASSERT_EQ(perturbed.lidars[j].points.size(), clean.lidars[j].points.size());
    EXPECT_NE(perturbed.lidars[j].points, clean.lidars[j].points);
    EXPECT_EQ(perturbed.lidars[j].points, again.lidars[j].points);  // same seed, same perturbation
    EXPECT_NE(perturbed.lidars[j].points, other.lidars[j].points);
    // tr(Xi) grows with the distance from the LiDAR (eq 6.7's rotation term): far points are the least certain.
    double near_u = 0.0, far_u = 0.0;
    for (std::size_t i = 0; i < perturbed.lidars[j].points.size(); ++i) {
      const double range = perturbed.lidars[j].points[i].head<2>().norm();
      if (range < 6.0) near_u = std::max(near_u, perturbed.lidars[j].uncertainty[i]);
      if (range > 15.0) far_u = std::max(far_u, perturbed.lidars[j].uncertainty[i]);
      ASSERT_GT(perturbed.lidars[j].uncertainty[i], 3.0 / 2500.0);
    }
    EXPECT_GT(far_u, near_u);
  }
}

TEST(DetectionFrames, OnlineCalibrationUndoesTheInjectedPerturbationAndShrinksTheUncertainty) {
  const fs::path folder = lyft_dataset(2, sim::DetectionLayout::kStreet);
  const DetectionDataset dataset = DetectionDataset::open(folder, true);
  const std::size_t ref = dataset.reference();
  const calib::PairRefineConfig online = online_refine_config();
  for (std::size_t k = 0; k < 2; ++k) {
    const DetectionFrame given = dataset.read(k, 0.1, 5);  // the largest alpha of Fig 6.5
    const DetectionFrame refined = dataset.read(k, 0.1, 5, &online);
    ASSERT_EQ(refined.placements.size(), dataset.lidar_names().size());
    const DetectionFrame again = dataset.read(k, 0.1, 5, &online);  // the registrations run in parallel: the same frame
    for (std::size_t j = 0; j < refined.placements.size(); ++j) {
      EXPECT_EQ(again.placements[j].T_base_lidar.matrix(), refined.placements[j].T_base_lidar.matrix());
      EXPECT_EQ(again.lidars[j].points, refined.lidars[j].points);
      EXPECT_EQ(again.lidars[j].uncertainty, refined.lidars[j].uncertainty);
    }
    EXPECT_FALSE(refined.placements[ref].refine_ran);
    EXPECT_EQ(refined.lidars[ref].points, given.lidars[ref].points);
    for (std::size_t j = 0; j < refined.placements.size(); ++j) {
      if (j == ref) continue;
      SCOPED_TRACE(dataset.lidar_names()[j] + " frame " + std::to_string(k));
      const LidarPlacement& placement = refined.placements[j];
      const SE3& truth = dataset.dataset_extrinsics()[j];
      EXPECT_TRUE(placement.refine_ran);
      EXPECT_NE(placement.refine_verdict, calib::PairVerdict::kNotConverged);
      EXPECT_EQ(placement.T_base_lidar_given.matrix(), given.placements[j].T_base_lidar.matrix());  // same draw
      const double before_deg = test::rotation_error_deg(truth, placement.T_base_lidar_given);
      const double after_deg = test::rotation_error_deg(truth, placement.T_base_lidar);
      const double before_m = test::translation_error_m(truth, placement.T_base_lidar_given);
      const double after_m = test::translation_error_m(truth, placement.T_base_lidar);
      // Seen (2026-12-06): 1.6-1.9 deg and 9-20 mm before, 0.006-0.08 deg and 0.4-2.2 mm after.
      EXPECT_GT(before_deg, 0.5);
      EXPECT_LT(after_deg, 0.15);
      EXPECT_LT(after_m, 0.01);
      EXPECT_LT(after_m, before_m);
      // The registration's covariance is far tighter than alpha 0.1's prior: every point's tr(Xi) shrinks.
      ASSERT_EQ(refined.lidars[j].uncertainty.size(), given.lidars[j].uncertainty.size());
      double given_sum = 0.0, refined_sum = 0.0;
      for (std::size_t i = 0; i < given.lidars[j].uncertainty.size(); ++i) {
        given_sum += given.lidars[j].uncertainty[i], refined_sum += refined.lidars[j].uncertainty[i];
        ASSERT_GT(refined.lidars[j].uncertainty[i], 3.0 / 2500.0 - 1e-15);  // never below the point noise
      }
      EXPECT_LT(refined_sum, 0.2 * given_sum);
    }
  }
}

TEST(DetectionFrames, ADatasetWithoutLabelsCannotTrain) {
  const fs::path folder = cars_dataset(1);
  fs::remove_all(folder / "groundtruth" / "label_2");
  EXPECT_NO_THROW(DetectionDataset::open(folder, false));
  try {
    DetectionDataset::open(folder, true);
    ADD_FAILURE() << "a dataset without labels was accepted for training";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no labels"), std::string::npos) << e.what();
  }
}

TEST(DetectionAugmentation, MovesPointsAndBoxesAlike) {
  AugmentConfig config;
  config.share = 1.0;
  std::mt19937_64 rng(5);
  const io::Box3D box{Vec3(12.0, -4.0, 0.1), 4.2, 1.8, 1.5, 0.7};
  int flips = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Augmentation a = draw_augmentation(config, true, rng);
    flips += a.flip_y ? 1 : 0;
    EXPECT_LE(std::abs(a.yaw), 5.0 * std::numbers::pi / 180.0 + 1e-12);
    EXPECT_LE(std::abs(a.translation.z()), 0.3);
    EXPECT_GE(a.scale, 0.95);
    EXPECT_LE(a.scale, 1.05);
    // The augmented box's corners are the augmented corners (as a set: a flip mirrors the order).
    const io::Box3D moved = augment_box(a, box);
    for (const Vec3& corner : corners(box)) {
      const Vec3 target = augment_point(a, corner);
      double nearest = 1e9;
      for (const Vec3& c : corners(moved)) nearest = std::min(nearest, (c - target).norm());
      EXPECT_LT(nearest, 1e-9);
    }
  }
  EXPECT_GT(flips, 10);
  EXPECT_LT(flips, 40);
  config.share = 0.0;
  const Augmentation none = draw_augmentation(config, true, rng);
  EXPECT_EQ(augment_point(none, Vec3(1, 2, 3)), Vec3(1, 2, 3));
}

}  // namespace
}  // namespace mlidar::detect
