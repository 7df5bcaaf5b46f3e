// Deskew inside the registration (MotionDeskew, scan_to_map.hpp) against an
// exact oracle: a noise-free room scanned during a constant-velocity motion
// (every point seen from the pose of its own time, eq 4.12's model), its
// features deskewed with a wrong velocity (zero, the kind of error a
// prediction a frame late makes). With the previous centroid pose known, the
// registration's fixed point is the true pose and the true velocity.
#include <cmath>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

#include "mlidar/slam/scan_to_map.hpp"
#include "slam/synthetic_scans.hpp"

namespace mlidar::slam {
namespace {

struct DistortedScan {
  std::vector<Eigen::Vector3f> world;     ///< the room seen at the centroid pose (identity): the map
  std::vector<Eigen::Vector3f> observed;  ///< features as measured during the sweep
  std::vector<float> times;               ///< their times from the centroid, s
};

DistortedScan distorted_room(const BodyVelocity& truth) {
  const LidarModel model = test::uniform_model(16, -15.0, 15.0, 0.4);
  const std::vector<test::AxisBox> boxes = {{{3.0, -1.0, -1.5}, {4.0, 1.0, 0.5}, 1}, {{-2.0, 3.0, -1.5}, {0.0, 4.5, 1.0}, 2}};
  const test::AxisBox room{{-8.0, -6.0, -1.5}, {9.0, 7.0, 2.5}, -1};
  DistortedScan out;
  out.world = test::cast_scan(model, -1.5, boxes, &room).scan.points;
  for (std::size_t i = 0; i < out.world.size(); i += 3) {
    const Vec3 p = out.world[i].cast<double>();
    // Sweep time from the azimuth: one turn in 0.1 s, centred on the centroid.
    const double azimuth = std::atan2(p.y(), p.x());
    const double tau = 0.05 * azimuth / std::numbers::pi;
    // Eq 4.12: p = Exp(tau w) p_obs + tau v, so p_obs = Exp(-tau w) (p - tau v).
    const Vec3 observed = so3_exp(-tau * truth.angular) * (p - tau * truth.linear);
    out.observed.push_back(observed.cast<float>());
    out.times.push_back(static_cast<float>(tau));
  }
  return out;
}

TEST(MotionDeskew, RecoversThePoseAndVelocityOfAConstantVelocitySweep) {
  BodyVelocity truth;
  truth.linear = Vec3(1.5, 0.4, 0.1);
  truth.angular = Vec3(0.05, -0.1, 0.9);
  const DistortedScan scan = distorted_room(truth);
  VoxelMap plane_map(1.0, 20), edge_map(1.0, 10);
  plane_map.add(scan.world);
  const double dt = 0.1;
  const SE3 T_world_previous = truth.pose_at(dt).inverse();  // the previous centroid, one frame before at this velocity
  const RegistrationConfig config;

  // Deskewed with zero velocity (the observed points as they are): the registration fits the distorted cloud.
  const RegistrationResult plain = register_scan_to_map({}, scan.observed, edge_map, plane_map, SE3::identity(), 0.3, config);
  const MotionDeskew motion{{}, scan.times, T_world_previous, dt, BodyVelocity{}};
  const RegistrationResult in_loop = register_scan_to_map({}, scan.observed, edge_map, plane_map, SE3::identity(), 0.3, config, &motion);

  const auto error = [](const SE3& T) { return T.translation().norm() + 10.0 * so3_log(T.rotation()).norm(); };  // m + 10 m x rad
  ASSERT_TRUE(in_loop.velocity_used.has_value());
  EXPECT_FALSE(plain.velocity_used.has_value());
  std::printf("pose error (m + 10 m x rad): zero-velocity deskew %.5f, in the registration %.5f\n", error(plain.T_world_base),
              error(in_loop.T_world_base));
  EXPECT_GT(error(plain.T_world_base), 0.01);  // the distortion matters (0.15 m and 5 deg over the sweep)
  EXPECT_LT(error(in_loop.T_world_base), 0.1 * error(plain.T_world_base));
  EXPECT_LT((in_loop.velocity_used->linear - truth.linear).norm(), 0.05);
  EXPECT_LT((in_loop.velocity_used->angular - truth.angular).norm(), 0.01);
  EXPECT_GT(in_loop.match_ratio(), 0.9);
}

}  // namespace
}  // namespace mlidar::slam
