// Dataset folders: every output round-trips through the io readers, the same
// seed gives the same bytes, points map onto the scene with the written
// ground truth, bad input leaves nothing behind.
#include <cmath>
#include <numbers>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/surface_samples.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/sim/corner_dataset.hpp"
#include "mlidar/sim/drive_dataset.hpp"
#include "mlidar/sim/ground_truth.hpp"
#include "test_support.hpp"

namespace mlidar::sim {
namespace {

namespace fs = std::filesystem;

DriveSpec small_street() {
  DriveSpec spec;
  spec.rig = named_rig("single-hdl64");
  spec.rig.lidars[0].model.horizontal_resolution_deg = 2.0;
  spec.rig.lidars[0].model.range_noise_sigma = 0.0;
  spec.rig.lidars[0].dropout_probability = 0.0;
  spec.scene = "street";
  spec.trajectory = SimTrajectory::named("vehicle", spec.rig.base_height);
  spec.frames = 3;
  spec.seed = 11;
  spec.perturb_deg = 2.0;
  spec.perturb_m = 0.1;
  return spec;
}

TEST(DriveDataset, RoundTripsThroughTheReaders) {
  DriveSpec spec = small_street();
  spec.rig = named_rig("rv");
  for (auto& lidar : spec.rig.lidars) lidar.model.horizontal_resolution_deg = 2.0;
  const fs::path out = test::scratch_dir() / "rv";
  write_drive_dataset(spec, out);
  const io::Dataset dataset = io::read_dataset_yaml(out);
  ASSERT_EQ(dataset.lidars.size(), 4u);
  EXPECT_EQ(dataset.base, "top");
  const auto stamps = io::read_times(out / dataset.times);
  ASSERT_EQ(stamps.size(), 3u);
  const Trajectory truth = io::read_tum(out / *dataset.groundtruth.trajectory);
  ASSERT_EQ(truth.size(), 3u);
  const io::Extrinsics extrinsics = io::read_extrinsics(out / *dataset.groundtruth.extrinsics);
  for (std::size_t i = 0; i < 4; ++i) {
    const auto* truth_i = extrinsics.find(dataset.lidars[i].name);
    ASSERT_NE(truth_i, nullptr);
    const SE3 error = truth_i->T_base_lidar.inverse() * *dataset.lidars[i].initial_extrinsic;
    if (i == 0) {
      EXPECT_NEAR(error.log().norm(), 0.0, 1e-12);  // the base LiDAR is not perturbed
    } else {
      EXPECT_NEAR(so3_log(error.rotation()).norm(), 2.0 * std::numbers::pi / 180.0, 1e-9);
    }
    const auto cloud = io::read_pcd(out / dataset.lidars[i].scans / "000002.pcd");
    for (const char* field : {"x", "y", "z", "intensity", "ring", "t"}) EXPECT_NE(cloud.table.find(field), nullptr) << field;
    EXPECT_GT(cloud.table.num_points, 100u);
  }
}

TEST(DriveDataset, SameSeedSameBytes) {
  const DriveSpec spec = small_street();
  const fs::path dir = test::scratch_dir();
  write_drive_dataset(spec, dir / "a");
  write_drive_dataset(spec, dir / "b");
  for (const auto& entry : fs::recursive_directory_iterator(dir / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), dir / "a");
    EXPECT_EQ(io::read_file_bytes(entry.path()), io::read_file_bytes(dir / "b" / relative)) << relative;
  }
}

TEST(DriveDataset, WrittenPointsLieInTheirWrittenBoxes) {
  // A parked-car-only check: points hitting a static labelled box, mapped to
  // the base frame at the frame stamp by the written truth, lie in the written box.
  DriveSpec spec = small_street();
  spec.trajectory = SimTrajectory::stationary(SE3(Quat::Identity(), Vec3(0.0, 0.0, spec.rig.base_height)));
  const fs::path out = test::scratch_dir() / "street";
  write_drive_dataset(spec, out);
  const auto boxes = io::read_kitti_labels(out / "groundtruth/boxes/000000.txt");
  ASSERT_FALSE(boxes.empty());
  const auto cloud = io::to_scan(io::read_pcd(out / "scans/lidar/000000.pcd").table, "scan");
  int inside = 0;
  for (const auto& box : boxes) {
    for (const auto& p : cloud.points) inside += box_contains(box, p.cast<double>(), 1e-4);
  }
  EXPECT_GT(inside, 20);
}

TEST(DriveDataset, SurfaceSamplesLieUnderTheNoiseFreePointsInTheFirstBaseFrame) {
  DriveSpec spec;
  spec.rig = named_rig("rhd");
  for (auto& lidar : spec.rig.lidars) {
    lidar.model.horizontal_resolution_deg = 2.0;
    lidar.model.range_noise_sigma = 0.0;
    lidar.dropout_probability = 0.0;
  }
  spec.scene = "room";
  const SE3 T_world_base(so3_exp(Vec3(0.0, 0.0, 0.7)), Vec3(1.0, -2.0, 1.3));  // not the identity: the frame matters
  spec.trajectory = SimTrajectory::stationary(T_world_base);
  spec.frames = 2;
  spec.surface_spacing_m = 0.05;
  const fs::path out = test::scratch_dir() / "surfaces";
  write_drive_dataset(spec, out);
  const io::SurfaceSamples surfaces = io::read_surface_samples(out / "groundtruth" / "surfaces.ply");
  ASSERT_GT(surfaces.points.size(), 1000u);
  // One sample per 5 cm cube at most.
  std::set<std::tuple<int, int, int>> cubes;
  for (const Eigen::Vector3f& p : surfaces.points)
    cubes.insert({static_cast<int>(std::floor(p.x() / 0.05F)), static_cast<int>(std::floor(p.y() / 0.05F)),
                  static_cast<int>(std::floor(p.z() / 0.05F))});
  EXPECT_EQ(cubes.size(), surfaces.points.size());
  const io::Extrinsics extrinsics = io::read_extrinsics(out / "groundtruth" / "extrinsics.yaml");
  std::size_t points = 0, on_surface = 0;
  for (const auto& lidar : extrinsics.lidars) {
    const Scan scan = io::to_scan(io::read_pcd(out / "scans" / lidar.name / "000001.pcd").table, lidar.name);
    for (const Eigen::Vector3f& p_lidar : scan.points) {
      const Eigen::Vector3f p = lidar.T_base_lidar * p_lidar;
      std::size_t nearest = 0;
      for (std::size_t k = 1; k < surfaces.points.size(); ++k)
        if ((surfaces.points[k] - p).squaredNorm() < (surfaces.points[nearest] - p).squaredNorm()) nearest = k;
      ++points;
      on_surface += std::abs(surfaces.normals[nearest].dot(p - surfaces.points[nearest])) < 2e-3F ? 1 : 0;
    }
  }
  ASSERT_GT(points, 1000u);
  EXPECT_GT(static_cast<double>(on_surface) / static_cast<double>(points), 0.98) << on_surface << " of " << points;
}

TEST(DriveDataset, BadRequestsLeaveNothingBehind) {
  const fs::path dir = test::scratch_dir();
  DriveSpec spec = small_street();
  spec.frames = 0;
  EXPECT_THROW(write_drive_dataset(spec, dir / "zero"), UsageError);
  spec = small_street();
  spec.scene = "moon";
  EXPECT_THROW(write_drive_dataset(spec, dir / "moon"), UsageError);
  EXPECT_TRUE(fs::is_empty(dir));  // checked before anything is written (which folder may be written: io::RunFolder)
}

TEST(CornerDataset, ThesisProtocolCloudsAndTruth) {
  CornerSpec spec;
  spec.angle_min = 60.0;
  spec.angle_max = 80.0;
  const fs::path out = test::scratch_dir() / "corner";
  write_corner_dataset(spec, out);
  const io::Dataset dataset = io::read_dataset_yaml(out);
  EXPECT_EQ(io::read_times(out / "times.txt").size(), 3u);
  const auto truth = io::read_extrinsics(out / "groundtruth/extrinsics.yaml");
  const SE3 T_l1_l2 = truth.find("l2")->T_base_lidar;
  EXPECT_NEAR(T_l1_l2.translation().x(), 0.8766, 1e-12);
  const auto l1 = io::to_scan(io::read_pcd(out / "scans/l1/000001.pcd").table, "l1");
  const auto l2 = io::to_scan(io::read_pcd(out / "scans/l2/000001.pcd").table, "l2");
  ASSERT_EQ(l1.size(), 9500u);
  ASSERT_EQ(l2.size(), 9500u);
  // Points within 0.3 m of the floor (z = -1.5 in l1's level frame): its 2500 points (|noise| < 3 sigma:
  // 99.7%), the walls' points below 0.3 m (2 x 2500 x 0.3/10) and outliers there (2000 x 0.3 m x
  // phi(1) / (5 m (Phi(1) - Phi(-1))) ~ 42): ~2685 expected.
  int floor_l1 = 0;
  int floor_l2 = 0;
  for (const auto& p : l1.points) floor_l1 += std::abs(p.z() + 1.5f) < 0.3f;
  for (const auto& p : l2.points) floor_l2 += std::abs((T_l1_l2 * Vec3(p.cast<double>())).z() + 1.5) < 0.3;
  EXPECT_NEAR(floor_l1, 2685, 120);
  EXPECT_NEAR(floor_l2, 2685, 120);
}

}  // namespace
}  // namespace mlidar::sim
