#pragma once
// Extrinsics YAML, the one file every stage reads and writes:
//   base: base
//   lidars:
//     top:
//       translation: [x, y, z]        # metres, p_base = R p_lidar + t
//       quaternion_wxyz: [w, x, y, z]
//       covariance: [36 numbers]      # optional, row-major 6x6, tx ty tz rx ry rz
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"

namespace mlidar::io {

struct LidarExtrinsic {
  std::string name;
  SE3 T_base_lidar;
  std::optional<Mat6> covariance;  ///< [t, r] order, rotation in the local tangent (rad)
};

struct Extrinsics {
  std::string base = "base";
  std::vector<LidarExtrinsic> lidars;  ///< file order
  /// nullptr when absent. Not on a temporary (`read_extrinsics(p).find(..)`
  /// would dangle: two use-after-frees in tests came from that pattern).
  const LidarExtrinsic* find(const std::string& name) const&;
  const LidarExtrinsic* find(const std::string& name) const&& = delete;
};

/// Rejects unknown keys, quaternions off unit length by more than 1e-6,
/// non-symmetric or non-PSD covariances, with the key named in the message.
Extrinsics parse_extrinsics(const std::string& yaml_text, const std::string& source);
Extrinsics read_extrinsics(const std::filesystem::path& path);
std::string format_extrinsics(const Extrinsics& extrinsics);  ///< full double precision
void write_extrinsics(const std::filesystem::path& path, const Extrinsics& extrinsics);

}  // namespace mlidar::io
