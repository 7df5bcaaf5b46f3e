#pragma once
// Simulated rigs: LiDARs with their models and true extrinsics T_base_lidar
// (p_base = R p_lidar + t), dropout and sweep start offsets.
//
// Named rigs (base = primary LiDAR unless stated):
//   rhd          two VLP-16 left/right: T_left_right = roll 40 deg, t (0, -0.477, -0.220)
//                (thesis Table 4.3, GT of the handheld rigs); base = left.
//   rv           four RS-LiDAR-16 top/front/left/right; base = top. front: pitch 10 deg,
//                t (0.795, 0, -1.364) (thesis Table 4.3 CAD model). left/right are not
//                published: assumed at (0.3, +-0.85, -0.95) rolled 15 deg outward-down.
//   lyft         vehicle frame base; TOP HDL-64E (1.197, 0, 1.828), FRONT_LEFT and
//                FRONT_RIGHT PandarQT-like at (3.473, 0.942, 0.543) / (3.498, -0.950, 0.547)
//                (Lyft Level 5 calibrated_sensor translations; rotations assumed level,
//                bumpers yawed +-45 deg outward; sweeps unsynchronised: offsets 0, 25, 50 ms).
//   single-vlp16, single-hdl64   one LiDAR, base = the LiDAR.
//
// Rig YAML (every key checked; unknown keys are errors):
//   name: myrig
//   base: base                  # name of the base frame (default: first LiDAR's name)
//   base_height: 1.8            # metres of the base frame above the ground
//   lidars:
//     - name: top               # [A-Za-z0-9_-]+, unique
//       model: VLP-16           # a known model, or a mapping {name, vertical_angles_deg: [...],
//                               #  horizontal_resolution_deg, min_range, max_range,
//                               #  range_noise_sigma, sweep_period}
//       translation: [0, 0, 0]  # metres
//       rotation_rpy_deg: [0, 0, 0]   # R = Rz(yaw) Ry(pitch) Rx(roll); or quaternion_wxyz: [w, x, y, z]
//       dropout: 0.0            # probability in [0, 1) that a return is lost
//       sweep_offset: 0.0       # seconds in [0, sweep_period): sweep start after the frame stamp
// All LiDARs of a rig share one sweep period (the frame period).
#include <filesystem>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::sim {

struct SimLidar {
  std::string name;
  LidarModel model;
  SE3 T_base_lidar;
  double dropout_probability = 0.0;
  double sweep_offset = 0.0;  ///< seconds after the frame stamp at which this LiDAR's sweep starts
};

struct SimRig {
  std::string name;
  std::string base_frame = "base";
  double base_height = 1.8;  ///< metres above the ground at rest
  std::vector<SimLidar> lidars;

  double frame_period() const { return lidars.empty() ? 0.1 : lidars.front().model.sweep_period; }
};

std::vector<std::string> rig_names();
/// A named rig; UsageError for unknown names.
SimRig named_rig(const std::string& name);
/// Parses and validates a rig YAML; InputError naming `source` and the key otherwise.
SimRig parse_rig_yaml(const std::string& text, const std::string& source);
/// A named rig, or a YAML file when `name_or_path` names an existing file or ends in .yaml/.yml.
SimRig load_rig(const std::string& name_or_path);

}  // namespace mlidar::sim
