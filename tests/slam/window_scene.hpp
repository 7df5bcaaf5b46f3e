#pragma once
// Noise-free synthetic window for the back-end tests and benchmark: world
// planes and lines, poses and extrinsics, and feature points that lie exactly
// on them (so every residual is zero at the true state).
#include <random>

#include <Eigen/LU>
#include <vector>

#include "mlidar/core/so3.hpp"
#include "mlidar/slam/window_problem.hpp"

namespace mlidar::slam::test {

struct WindowScene {
  std::vector<PlaneCoefficients> planes;
  std::vector<std::pair<Vec3, Vec3>> lines;  ///< point, unit direction
};

/// A 20 m room: six walls, four slanted planes and `line_count` random lines.
inline WindowScene room_scene(int line_count, std::mt19937_64& rng) {
  WindowScene scene;
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {1.0, -1.0}) scene.planes.push_back({sign * Vec3::Unit(axis), 10.0});
  for (const Vec3& n : {Vec3(1, 1, 0), Vec3(0, 1, 1), Vec3(1, 0, -1), Vec3(1, -2, 1)}) scene.planes.push_back({n.normalized(), 6.0});
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int k = 0; k < line_count; ++k)
    scene.lines.emplace_back(Vec3(normal(rng), normal(rng), normal(rng)) * 4.0, Vec3(normal(rng), normal(rng), normal(rng)).normalized());
  return scene;
}

/// Vertical walls only (every normal is perpendicular to z): a z shift is unobservable.
inline WindowScene corridor_scene() {
  WindowScene scene;
  for (int k = 0; k < 6; ++k) {
    const double angle = 0.5 * k;
    scene.planes.push_back({Vec3(std::cos(angle), std::sin(angle), 0.0), 8.0});
  }
  return scene;
}

/// `per_lidar` features per (frame, lidar): 3 in 4 on planes, the rest on lines
/// (planes only when the scene has no lines), within ~8 m of the LiDAR.
inline WindowProblem observe(const WindowScene& scene, const WindowState& truth, int per_lidar, std::mt19937_64& rng) {
  std::uniform_int_distribution<std::size_t> pick_plane(0, scene.planes.size() - 1);
  std::uniform_int_distribution<std::size_t> pick_line(0, scene.lines.empty() ? 0 : scene.lines.size() - 1);
  std::uniform_real_distribution<double> spread(-8.0, 8.0);
  WindowProblem problem;
  for (int i = 0; i < static_cast<int>(truth.T_world_base.size()); ++i)
    for (int j = 0; j < static_cast<int>(truth.T_base_lidar.size()); ++j) {
      const SE3 T_lidar_world =
          (truth.T_world_base[static_cast<std::size_t>(i)] * truth.T_base_lidar[static_cast<std::size_t>(j)]).inverse();
      const Vec3 origin = T_lidar_world.inverse().translation();
      for (int k = 0; k < per_lidar; ++k) {
        const Vec3 near = origin + Vec3(spread(rng), spread(rng), spread(rng));
        if (scene.lines.empty() || k % 4 != 0) {
          const PlaneCoefficients& plane = scene.planes[pick_plane(rng)];
          const Vec3 q = near - (plane.normal.dot(near) + plane.offset) * plane.normal;
          problem.planes.push_back({i, j, T_lidar_world * q, plane});
        } else {
          const auto& [a, u] = scene.lines[pick_line(rng)];
          const Vec3 q = a + u.dot(near - a) * u;
          problem.edges.push_back({i, j, T_lidar_world * q, a, u});
        }
      }
    }
  return problem;
}

/// Exp(delta) T with delta = [translation_m along a random unit axis, rotation_rad about another].
inline SE3 perturb(const SE3& T, double translation_m, double rotation_rad, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Vec6 delta;
  delta << Vec3(normal(rng), normal(rng), normal(rng)).normalized() * translation_m,
      Vec3(normal(rng), normal(rng), normal(rng)).normalized() * rotation_rad;
  return SE3::exp(delta) * T;
}

/// Eq 4.41 written out with an explicit inverse: the Schur complement of H dx = -g onto every column after the
/// first 6 (the first pose eliminated), the reference the marginalization tests compare against.
inline void schur_without_first_pose(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Eigen::MatrixXd& schur_H,
                                     Eigen::VectorXd& schur_g) {
  const Eigen::Index n = H.rows();
  const Eigen::MatrixXd H_mm_inv = H.topLeftCorner(6, 6).inverse();
  const Eigen::MatrixXd H_rm = H.bottomLeftCorner(n - 6, 6);
  schur_H = H.bottomRightCorner(n - 6, n - 6) - H_rm * H_mm_inv * H_rm.transpose();
  schur_g = g.tail(n - 6) - H_rm * H_mm_inv * g.head(6);
}

/// A Huber scale no residual reaches: every weight 1.
inline constexpr double kHuberOff = 1e6;

/// Tangent distance |Log(a b^-1)|.
inline double distance(const SE3& a, const SE3& b) { return (a * b.inverse()).log().norm(); }

}  // namespace mlidar::slam::test
