// Rigs (named and YAML) and smooth trajectories.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/sim/rig.hpp"
#include "mlidar/sim/trajectory.hpp"

namespace mlidar::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(Rigs, ThesisExtrinsics) {
  const SimRig rhd = named_rig("rhd");
  ASSERT_EQ(rhd.lidars.size(), 2u);
  EXPECT_TRUE(rhd.lidars[0].T_base_lidar.log().isZero(0.0));
  const SE3& right = rhd.lidars[1].T_base_lidar;
  EXPECT_NEAR(right.translation().y(), -0.477, 1e-12);
  EXPECT_NEAR(so3_log(right.rotation()).x(), 40.0 * kDeg, 1e-12);
  const SimRig rv = named_rig("rv");
  ASSERT_EQ(rv.lidars.size(), 4u);
  EXPECT_EQ(rv.base_frame, "top");
  EXPECT_TRUE(rv.lidars[0].T_base_lidar.log().isZero(0.0));
  EXPECT_NEAR(so3_log(rv.lidars[1].T_base_lidar.rotation()).y(), 10.0 * kDeg, 1e-12);
  EXPECT_TRUE(rv.lidars[1].T_base_lidar.translation().isApprox(Vec3(0.795, 0.0, -1.364)));
  const SimRig lyft = named_rig("lyft");
  EXPECT_EQ(lyft.base_frame, "vehicle");
  EXPECT_TRUE(lyft.lidars[2].T_base_lidar.translation().isApprox(Vec3(3.498, -0.950, 0.547)));
  EXPECT_THROW(named_rig("tractor"), UsageError);
}

TEST(Rigs, YamlRoundTripOfTheSchema) {
  const SimRig rig = parse_rig_yaml(R"(
name: pair
base_height: 1.2
lidars:
  - {name: a, model: OS1-64}
  - name: b
    model: {name: tiny, vertical_angles_deg: [5, -5, 0], horizontal_resolution_deg: 1.0, max_range: 40}
    translation: [1, 2, 3]
    rotation_rpy_deg: [0, 0, 90]
    dropout: 0.1
    sweep_offset: 0.05
)",
                                    "rig.yaml");
  EXPECT_EQ(rig.base_frame, "a");
  ASSERT_EQ(rig.lidars.size(), 2u);
  EXPECT_EQ(rig.lidars[1].model.vertical_angles_deg, (std::vector<double>{-5, 0, 5}));
  EXPECT_TRUE((rig.lidars[1].T_base_lidar * Vec3(Vec3::UnitX())).isApprox(Vec3(1.0, 3.0, 3.0)));
  EXPECT_DOUBLE_EQ(rig.lidars[1].sweep_offset, 0.05);
}

TEST(Rigs, MalformedYamlNamesTheKey) {
  auto expect_error = [](const std::string& text, const std::string& key) {
    try {
      parse_rig_yaml(text, "bad.yaml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), key) << e.what();
      EXPECT_EQ(e.file(), "bad.yaml");
    }
  };
  expect_error("lidars: [", "(document)");
  expect_error("lidars: []", "lidars");
  expect_error("lidars: [{name: a, model: VLP-16, colour: red}]", "lidars[0].colour");
  expect_error("lidars: [{name: a, model: VLP-99}]", "lidars[0].model");
  expect_error("lidars: [{name: a, model: VLP-16, translation: [1, 2]}]", "lidars[0].translation");
  expect_error("lidars: [{name: a, model: VLP-16, quaternion_wxyz: [1, 1, 0, 0]}]", "lidars[0].quaternion_wxyz");
  expect_error("lidars: [{name: a, model: VLP-16}, {name: a, model: VLP-16}]", "lidars[1].name");
  expect_error("lidars: [{name: ../x, model: VLP-16}]", "lidars[0].name");
  expect_error("lidars: [{name: a, model: VLP-16, dropout: 1.5}]", "lidars[0].dropout");
  expect_error("lidars: [{name: a, model: {vertical_angles_deg: [100]}}]", "lidars[0].model.vertical_angles_deg");
}

double speed(const SimTrajectory& trajectory, double t) {
  const double h = 1e-4;
  return (trajectory.T_world_base(t + h).translation() - trajectory.T_world_base(t - h).translation()).norm() / (2 * h);
}

TEST(Trajectories, RealisticSpeedsAndExcitation) {
  const auto walk = SimTrajectory::named("handheld", 1.3);
  const auto drive = SimTrajectory::named("vehicle", 1.9);
  Vec3 max_tilt = Vec3::Zero();
  for (double t = 0.0; t < 30.0; t += 0.25) {
    EXPECT_GT(speed(walk, t), 0.6);
    EXPECT_LT(speed(walk, t), 1.4);
    EXPECT_GT(speed(drive, t), 3.5);  // slower in the turns
    EXPECT_LT(speed(drive, t), 8.0);
    const SE3 car = drive.T_world_base(t);
    EXPECT_NEAR(car.translation().z(), 1.9, 1e-12);
    EXPECT_NEAR((car.rotation() * Vec3::UnitZ()).z(), 1.0, 1e-12);  // planar: no roll or pitch
    max_tilt = max_tilt.cwiseMax(so3_log(walk.T_world_base(t).rotation()).cwiseAbs());
  }
  EXPECT_GT(max_tilt.x(), 0.1);  // handheld rotates about all three axes
  EXPECT_GT(max_tilt.y(), 0.1);
  EXPECT_GT(max_tilt.z(), 0.5);
  EXPECT_THROW(SimTrajectory::named("flying", 1.0), UsageError);
}

TEST(Trajectories, SplineFollowsPosesAndIsC2) {
  // Poses sampled from the handheld trajectory at 20 Hz; the spline must stay close to them.
  const auto walk = SimTrajectory::named("handheld", 1.3);
  Trajectory poses;
  for (int k = 0; k <= 200; ++k) poses.poses.push_back({0.05 * k, walk.T_world_base(0.05 * k)});
  const auto spline = SimTrajectory::through(poses, 0.05);
  EXPECT_DOUBLE_EQ(spline.start_time(), 0.0);
  EXPECT_NEAR(spline.end_time(), 10.0, 1e-9);
  for (double t = 0.5; t < 9.5; t += 0.37) {
    const SE3 error = walk.T_world_base(t).inverse() * spline.T_world_base(t);
    EXPECT_LT(error.translation().norm(), 0.01) << t;
    EXPECT_LT(so3_log(error.rotation()).norm(), 0.01) << t;
  }
  // C2: the second difference of position is continuous across a knot (t = 2.0).
  auto accel = [&](double t) {
    const double h = 1e-4;
    return Vec3(
        (spline.T_world_base(t + h).translation() - 2 * spline.T_world_base(t).translation() + spline.T_world_base(t - h).translation()) /
        (h * h));
  };
  // A jump in acceleration would be O(1 m/s^2); the jerk over 4e-4 s is ~0.02.
  EXPECT_LT((accel(2.0 - 2e-4) - accel(2.0 + 2e-4)).norm(), 0.05);
}

}  // namespace
}  // namespace mlidar::sim
