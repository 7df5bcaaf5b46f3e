// Spinning acquisition: points lie on surfaces, times increase per ring,
// undistortion by the true trajectory removes the motion, labelled points
// fall in their boxes, the seed fixes the output.
#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/lidar_models.hpp"
#include "mlidar/sim/scenes.hpp"

namespace mlidar::sim {
namespace {

/// Independent oracle: distance from p to the surface of one primitive
/// (+inf when p's projection falls outside a bounded face).
double surface_distance(const Primitive& s, const Vec3& p) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  switch (s.kind) {
    case PrimitiveKind::kRectangle: {
      const Vec3 local = s.axes.transpose() * (p - s.centre);
      const bool inside = std::abs(local.x()) <= s.half_extent.x() + 1e-6 && std::abs(local.y()) <= s.half_extent.y() + 1e-6;
      return inside ? std::abs(local.z()) : inf;
    }
    case PrimitiveKind::kBox: {
      const Vec3 local = s.axes.transpose() * (p - s.centre);
      const Vec3 gap = local.cwiseAbs() - s.half_extent;  // distance to each slab face
      if ((gap.array() > 1e-6).any()) return (gap.array() > 1e-6).count() == 1 ? gap.maxCoeff() : inf;
      return std::abs(gap.maxCoeff());
    }
    case PrimitiveKind::kCylinder: {
      const Vec3 local = p - s.centre;
      const double radial = std::hypot(local.x(), local.y());
      const double side = std::abs(local.z()) <= s.half_extent.z() + 1e-6 ? std::abs(radial - s.radius) : inf;
      const double cap = radial <= s.radius + 1e-6 ? std::abs(std::abs(local.z()) - s.half_extent.z()) : inf;
      return std::min(side, cap);
    }
    case PrimitiveKind::kSphere:
      return std::abs((p - s.centre).norm() - s.radius);
    case PrimitiveKind::kGround: {
      const Vec3 normal = Vec3(-s.slope.x(), -s.slope.y(), 1.0).normalized();
      return std::abs(normal.dot(p - s.centre));
    }
  }
  return inf;
}

double scene_distance(const std::vector<Primitive>& primitives, const Vec3& p, double time) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : primitives) best = std::min(best, surface_distance(s.at_time(time), p));
  return best;
}

SimLidar noiseless(const char* model_name, double horizontal_deg) {
  SimLidar lidar;
  lidar.name.assign("lidar");
  lidar.model = lidar_model(model_name);
  lidar.model.range_noise_sigma = 0.0;
  lidar.model.horizontal_resolution_deg = horizontal_deg;
  lidar.T_base_lidar = SE3(so3_exp(Vec3(0.1, -0.2, 0.3)), Vec3(0.3, -0.2, 0.1));
  return lidar;
}

std::vector<Vec3> path_of(const SimTrajectory& trajectory, double duration) {
  std::vector<Vec3> path;
  for (double t = 0.0; t <= duration; t += 0.1) path.push_back(trajectory.T_world_base(t).translation());
  return path;
}

/// Max distance to the scene of the points mapped to the world by the pose at `pose_time(point time)`.
template <typename PoseTime>
double max_surface_error(const SimulatedScan& sweep, const SimLidar& lidar, const SimTrajectory& trajectory,
                         const std::vector<Primitive>& primitives, PoseTime pose_time) {
  double worst = 0.0;
  for (std::size_t i = 0; i < sweep.scan.size(); i += 7) {
    const double t = sweep.scan.stamp + sweep.scan.time[i];
    const SE3 T_world_lidar = trajectory.T_world_base(pose_time(t)) * lidar.T_base_lidar;
    worst = std::max(worst, scene_distance(primitives, T_world_lidar * Vec3(sweep.scan.points[i].cast<double>()), t));
  }
  return worst;
}

TEST(Acquisition, StaticNoiselessPointsLieOnSurfaces) {
  const SimLidar lidar = noiseless("VLP-16", 2.0);
  const auto trajectory = SimTrajectory::stationary(SE3(so3_exp(Vec3(0.0, 0.0, 0.7)), Vec3(1.0, 2.0, 1.5)));
  for (const auto& name : scene_names()) {
    const Scene scene = make_scene(name, 4, path_of(trajectory, 0.0));
    const auto sweep = simulate_sweep(scene, lidar, trajectory, 0.0, 1);
    ASSERT_GT(sweep.scan.size(), 500u) << name;
    ASSERT_TRUE(sweep.scan.is_consistent());
    EXPECT_LT(max_surface_error(sweep, lidar, trajectory, scene.primitives(), [](double t) { return t; }), 1e-5) << name;
  }
}

TEST(Acquisition, TimesIncreaseWithinEachRing) {
  const SimLidar lidar = noiseless("RS-LiDAR-16", 1.0);
  const auto trajectory = SimTrajectory::named("vehicle", 1.9);
  const Scene scene = make_scene("campus", 2, path_of(trajectory, 1.0));
  const auto sweep = simulate_sweep(scene, lidar, trajectory, 0.5, 3);
  std::vector<float> last(lidar.model.rings(), -1.0f);
  for (std::size_t i = 0; i < sweep.scan.size(); ++i) {
    const auto ring = sweep.scan.ring[i];
    ASSERT_LT(ring, lidar.model.rings());
    EXPECT_GT(sweep.scan.time[i], last[ring]);
    last[ring] = sweep.scan.time[i];
    EXPECT_GE(sweep.scan.time[i], 0.0f);
    EXPECT_LT(sweep.scan.time[i], 0.1f);
  }
}

TEST(Acquisition, UndistortingByTheTrueTrajectoryRemovesTheMotion) {
  const SimLidar lidar = noiseless("VLP-16", 1.0);
  for (const char* motion : {"handheld", "vehicle"}) {
    const auto trajectory = SimTrajectory::named(motion, 1.5);
    const Scene scene = make_scene("campus", 5, path_of(trajectory, 3.0));
    const double stamp = 2.0;
    const auto sweep = simulate_sweep(scene, lidar, trajectory, stamp, 9);
    const auto primitives = scene.primitives();
    // Each point re-projected with the pose at its own firing time lies on the scene ...
    EXPECT_LT(max_surface_error(sweep, lidar, trajectory, primitives, [](double t) { return t; }), 1e-5) << motion;
    // ... while treating the sweep as taken at the frame stamp does not.
    EXPECT_GT(max_surface_error(sweep, lidar, trajectory, primitives, [&](double) { return stamp; }), 0.05) << motion;
  }
}

TEST(Acquisition, LabelledPointsFallInTheirBoxes) {
  SimLidar lidar = noiseless("HDL-64E", 1.0);
  const auto trajectory = SimTrajectory::named("vehicle", 1.8);
  const Scene scene = make_scene("street", 8, path_of(trajectory, 2.0));
  const auto sweep = simulate_sweep(scene, lidar, trajectory, 1.0, 2);
  int labelled = 0;
  for (std::size_t i = 0; i < sweep.scan.size(); ++i) {
    const int id = sweep.object_id[i];
    if (id < 0) continue;
    ++labelled;
    const double t = sweep.scan.stamp + sweep.scan.time[i];
    const Vec3 p = (trajectory.T_world_base(t) * lidar.T_base_lidar) * Vec3(sweep.scan.points[i].cast<double>());
    EXPECT_TRUE(scene.objects()[static_cast<std::size_t>(id - 1)].contains(p, t, 1e-5));
  }
  EXPECT_GT(labelled, 50);
}

TEST(Acquisition, SameSeedSameSweepNoiseAndDropoutApplied) {
  SimLidar lidar = noiseless("VLP-16", 1.0);
  lidar.model.range_noise_sigma = 0.05;
  lidar.dropout_probability = 0.2;
  const auto trajectory = SimTrajectory::stationary(SE3(Quat::Identity(), Vec3(0.0, 0.0, 1.5)));
  const Scene scene = make_scene("room", 1, path_of(trajectory, 0.0));
  const auto a = simulate_sweep(scene, lidar, trajectory, 0.0, 42);
  const auto b = simulate_sweep(scene, lidar, trajectory, 0.0, 42);
  const auto c = simulate_sweep(scene, lidar, trajectory, 0.0, 43);
  EXPECT_EQ(a.scan.points, b.scan.points);
  EXPECT_NE(a.scan.points, c.scan.points);
  lidar.dropout_probability = 0.0;
  lidar.model.range_noise_sigma = 0.0;
  const auto full = simulate_sweep(scene, lidar, trajectory, 0.0, 42);
  const double kept = static_cast<double>(a.scan.size()) / static_cast<double>(full.scan.size());
  EXPECT_NEAR(kept, 0.8, 0.03);
  EXPECT_NE(sweep_seed(1, 0, 1), sweep_seed(1, 1, 0));
}

}  // namespace
}  // namespace mlidar::sim
