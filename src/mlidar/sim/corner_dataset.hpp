#pragma once
// `mlidar simulate corner`: the synthetic protocol of the thesis's plane-based
// calibration (Sec. 2.4.2, Tables 2.2-2.3). Per frame, two LiDAR clouds of
// `points` points each: (points - outliers) spread evenly over three planes
// (walls Pi1, Pi2 meeting on the z axis at angle alpha, floor Pi3 between
// them, each 10 m across) with isotropic N(0, noise^2) noise, plus
// `outliers` points N(0, 5^2 m^2) about the middle of the 10 m cube,
// rejected outside it. Frame k uses alpha = angle_min + k * angle_step up to
// angle_max (deg), listed in groundtruth/corner_angles.txt.
// l1 stands 4 m from the corner on the bisector, 1.5 m up, facing it.
// T_l1_l2 is configuration 1 or 2 of Table 2.2, whose rotation triplets we
// read as ZYX Euler angles (yaw, pitch, roll; R = Rz Ry Rx, rad):
//   1: (2.7337, -0.3946, -0.1809), t (0.8766, 0.4672, 1.0474)
//   2: (-0.5174, 0.1277, 0.1222),  t (1.3785, -1.3929, 1.3020)
// or, configuration 0, drawn from the seed (yaw in [0, 360), pitch and roll
// in [0, 20) deg, t in [-1.5, 1.5]^3 m). Written: scans/l1, scans/l2 (PCD,
// x y z in each LiDAR's frame), times.txt (0, 1, 2, ... s),
// groundtruth/extrinsics.yaml (base l1), dataset.yaml.
#include <cstdint>
#include <filesystem>

namespace mlidar::sim {

struct CornerSpec {
  std::uint64_t seed = 1;
  double noise = 0.1;
  int outliers = 2000;
  int points = 9500;
  double angle_min = 60.0;
  double angle_max = 120.0;
  double angle_step = 10.0;
  int configuration = 1;  ///< 1 or 2 (Table 2.2), 0 = random from the seed
};

/// Writes into the folder `out` as write_drive_dataset does. UsageError for counts or angles out of range.
void write_corner_dataset(const CornerSpec& spec, const std::filesystem::path& out);

}  // namespace mlidar::sim
