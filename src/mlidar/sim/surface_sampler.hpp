#pragma once
// The scene's true surfaces where the LiDARs saw them: the exact (noise-free)
// hits on static scenery, one per cube of `spacing` metres (the first hit to
// fall in it), with the surface normal there. Written as
// groundtruth/surfaces.ply (io/surface_samples.hpp) for `mlidar eval map
// --gt-surfaces`.
#include <cstdint>
#include <unordered_set>

#include "mlidar/core/se3.hpp"
#include "mlidar/io/surface_samples.hpp"

namespace mlidar::sim {

class SurfaceSampler {
 public:
  /// `T_frame_world` maps the simulator's world into the frame the samples are kept in.
  SurfaceSampler(double spacing, const SE3& T_frame_world);

  /// An exact hit in the world frame and its unit normal.
  void add(const Vec3& point_world, const Vec3& normal_world);

  const io::SurfaceSamples& samples() const { return samples_; }

 private:
  double spacing_;
  SE3 T_frame_world_;
  Mat3 R_frame_world_;
  std::unordered_set<std::uint64_t> occupied_;
  io::SurfaceSamples samples_;
};

}  // namespace mlidar::sim
