#pragma once
// Noise-free ray casting against axis-aligned boxes and a ground plane for
// the front-end tests: every point's true surface is known.
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/types.hpp"

namespace mlidar::slam::test {

struct AxisBox {
  Eigen::Vector3d min, max;
  int id = 0;
};

struct CastScan {
  Scan scan;
  std::vector<int> hit_id;  ///< box id, 0 = ground, -1 for room walls
};

inline LidarModel uniform_model(int rings, double low_deg, double high_deg, double horizontal_deg) {
  LidarModel model;
  model.name = "test";
  for (int r = 0; r < rings; ++r) model.vertical_angles_deg.push_back(low_deg + (high_deg - low_deg) * r / (rings - 1));
  model.horizontal_resolution_deg = horizontal_deg;
  model.min_range = 0.3;
  model.max_range = 100.0;
  return model;
}

/// Ray/box slab test from the origin along unit d: entry distance, or +inf.
inline double hit_box(const AxisBox& box, const Eigen::Vector3d& d) {
  double near = 0.0, far = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (0.0 < box.min[a] || 0.0 > box.max[a]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double t0 = box.min[a] / d[a], t1 = box.max[a] / d[a];
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
  }
  return near <= far && near > 0.0 ? near : std::numeric_limits<double>::infinity();
}

/// Casts every (ring, column) ray from the origin against the ground z = ground_z,
/// the boxes, and optionally the inside of a room box (exit distance).
inline CastScan cast_scan(const LidarModel& model, double ground_z, const std::vector<AxisBox>& boxes, const AxisBox* room = nullptr) {
  CastScan out;
  const int cols = static_cast<int>(std::lround(360.0 / model.horizontal_resolution_deg));
  for (int c = 0; c < cols; ++c) {
    const double azimuth = -2.0 * std::numbers::pi * c / cols;
    for (std::size_t r = 0; r < model.rings(); ++r) {
      const double elevation = model.vertical_angles_deg[r] * std::numbers::pi / 180.0;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      double best = std::numeric_limits<double>::infinity();
      int id = -2;
      if (d.z() < -1e-9) {
        best = ground_z / d.z();
        id = 0;
      }
      for (const auto& box : boxes) {
        const double t = hit_box(box, d);
        if (t < best) {
          best = t;
          id = box.id;
        }
      }
      if (room != nullptr) {
        double exit = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 3; ++a) {
          if (std::abs(d[a]) < 1e-12) continue;
          exit = std::min(exit, (d[a] > 0 ? room->max[a] : room->min[a]) / d[a]);
        }
        if (exit < best) {
          best = exit;
          id = -1;
        }
      }
      if (!std::isfinite(best) || best > model.max_range) continue;
      out.scan.points.push_back((best * d).cast<float>());
      out.scan.ring.push_back(static_cast<std::uint16_t>(r));
      out.hit_id.push_back(id);
    }
  }
  return out;
}

}  // namespace mlidar::slam::test
