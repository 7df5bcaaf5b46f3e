#include "mlidar/sim/acquisition.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "mlidar/sim/lidar_models.hpp"

namespace mlidar::sim {
namespace {

/// SplitMix64 finaliser (Steele, Lea & Flood, OOPSLA 2014).
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// Unit beam directions in the LiDAR frame, column-major: [column][ring].
std::vector<Vec3> beam_directions(const LidarModel& model, int columns) {
  std::vector<Vec3> directions;
  directions.reserve(static_cast<std::size_t>(columns) * model.rings());
  for (int c = 0; c < columns; ++c) {
    const double azimuth = -2.0 * std::numbers::pi * c / columns;
    for (const double elevation_deg : model.vertical_angles_deg) {
      const double elevation = elevation_deg * std::numbers::pi / 180.0;
      directions.emplace_back(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    }
  }
  return directions;
}

}  // namespace

std::uint64_t sweep_seed(std::uint64_t seed, std::uint64_t frame, std::uint64_t lidar) {
  return mix(mix(mix(seed) ^ frame) ^ (lidar + 0x632be59bd9b4e019ULL));
}

SimulatedScan simulate_sweep(const Scene& scene, const SimLidar& lidar, const SimTrajectory& trajectory, double frame_stamp,
                             std::uint64_t seed) {
  const LidarModel& model = lidar.model;
  const int columns = columns_per_sweep(model);
  const std::size_t rings = model.rings();
  const std::vector<Vec3> directions = beam_directions(model, columns);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);

  SimulatedScan out;
  out.scan.stamp = frame_stamp;
  for (int c = 0; c < columns; ++c) {
    const double t_rel = lidar.sweep_offset + model.sweep_period * c / columns;
    const double time = frame_stamp + t_rel;
    const SE3 T_world_lidar = trajectory.T_world_base(time) * lidar.T_base_lidar;
    const Mat3 R = T_world_lidar.rotation_matrix();
    for (std::size_t ring = 0; ring < rings; ++ring) {
      const Vec3& d_lidar = directions[static_cast<std::size_t>(c) * rings + ring];
      const Ray ray{T_world_lidar.translation(), R * d_lidar};
      const auto hit = scene.cast(ray, 0.0, model.max_range, time);
      if (!hit || hit->t < model.min_range) continue;
      const double range = hit->t + model.range_noise_sigma * noise(rng);
      if (uniform(rng) < lidar.dropout_probability || range <= 0.0) continue;
      out.scan.points.push_back((range * d_lidar).cast<float>());
      out.scan.intensity.push_back(static_cast<float>(255.0 * hit->reflectivity * std::abs(hit->normal.dot(ray.direction))));
      out.scan.ring.push_back(static_cast<std::uint16_t>(ring));
      out.scan.time.push_back(static_cast<float>(t_rel));
      out.object_id.push_back(hit->object_id);
      if (hit->object_id < 0) {
        out.scenery_hits.push_back(ray.origin + hit->t * ray.direction);
        out.scenery_normals.push_back(hit->normal);
      }
    }
  }
  return out;
}

}  // namespace mlidar::sim
