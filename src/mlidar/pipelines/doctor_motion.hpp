#pragma once
// `mlidar doctor`'s motion check: is there motion enough for the hand-eye
// calibration (slam's online calibration, calibrate auto)? The base LiDAR's
// own odometry (its scans alone, default settings) gives its poses; the
// hand-eye sees relative rotations, here those between frames about 0.5 s
// apart. It needs turns (eq 3.5-3.7), and about at least two axes: with every
// rotation about one axis (a ground vehicle) the translation along that axis
// is unobservable (eq 3.8-3.12; slam takes it from the ground planes instead).
// The spread is the ratio sqrt(e2 / e1) of the two largest eigenvalues of
// sum u u^T over the turning pairs' unit axes u (0: one axis, 1: two axes alike).
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"
#include "mlidar/core/types.hpp"
#include "mlidar/io/frame_source.hpp"

namespace mlidar::slam {
class Odometry;
}

namespace mlidar::pipelines {

struct MotionCheckConfig {
  double pair_seconds = 0.5;  ///< the relative rotations compared are about this far apart
  double turn_deg = 2.0;      ///< a pair turns when its rotation is at least this
  std::size_t min_turning_pairs = 3;
  double min_axis_spread = 0.15;  ///< below: every turn about one axis (planar motion)
};

struct MotionSummary {
  std::size_t frames = 0;         ///< scans given
  std::size_t registered = 0;     ///< registered by the odometry (not lost)
  std::size_t pairs = 0;          ///< relative rotations compared
  std::size_t turning_pairs = 0;  ///< of which turn at least turn_deg
  double largest_turn_deg = 0.0;
  double axis_spread = 0.0;        ///< sqrt(e2 / e1), see above; 0 with fewer than 2 turning pairs
  Vec3 main_axis = Vec3::UnitZ();  ///< the base frame's axis most turns are about (unit)
};

/// Feeds the base LiDAR's scans, in frame order, to its own odometry.
class BaseMotion {
 public:
  explicit BaseMotion(const io::SourceLidar& base);
  ~BaseMotion();
  BaseMotion(BaseMotion&&) noexcept;
  BaseMotion& operator=(BaseMotion&&) noexcept;

  void add(double stamp, const std::optional<Scan>& scan);
  MotionSummary summary(double frame_period, const MotionCheckConfig& config) const;

 private:
  std::unique_ptr<slam::Odometry> odometry_;
  std::vector<std::optional<SE3>> poses_;  ///< T_world_base per frame; nullopt when lost
};

}  // namespace mlidar::pipelines
