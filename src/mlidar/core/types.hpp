#pragma once
// Plain data types passed between stages. No behaviour beyond invariants checks.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"

namespace mlidar {

/// One sweep of one LiDAR. Geometry is contiguous xyz (float) so hot loops
/// stream memory; optional channels are parallel arrays, empty when absent.
struct Scan {
  double stamp = 0.0;                   ///< sweep start, seconds
  std::vector<Eigen::Vector3f> points;  ///< in the LiDAR frame, metres
  std::vector<float> intensity;         ///< empty or points.size()
  std::vector<std::uint16_t> ring;      ///< empty or points.size()
  std::vector<float> time;              ///< seconds from stamp; empty or points.size()

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_intensity() const { return !intensity.empty(); }
  bool has_ring() const { return !ring.empty(); }
  bool has_time() const { return !time.empty(); }
  /// True when every present channel has one entry per point.
  bool is_consistent() const;
};

/// Intrinsic description of a spinning LiDAR.
struct LidarModel {
  std::string name;                         ///< e.g. "VLP-16"
  std::vector<double> vertical_angles_deg;  ///< one per ring, ring order
  double horizontal_resolution_deg = 0.2;
  double min_range = 0.5;          ///< metres
  double max_range = 100.0;        ///< metres
  double range_noise_sigma = 0.0;  ///< metres, 1-sigma Gaussian
  double sweep_period = 0.1;       ///< seconds per revolution

  std::size_t rings() const { return vertical_angles_deg.size(); }
};

/// The scans of all LiDARs at one time step, in rig order.
struct Frame {
  double stamp = 0.0;
  std::vector<Scan> scans;
};

struct StampedPose {
  double stamp = 0.0;
  SE3 T_world_base;
};

/// Poses in increasing time order.
struct Trajectory {
  std::vector<StampedPose> poses;
  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
};

}  // namespace mlidar
