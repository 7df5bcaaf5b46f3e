#pragma once
// Trajectory files: TUM (`t x y z qx qy qz qw` per line, '#' comments) and
// KITTI odometry poses (12 numbers per line: the top 3x4 of T_world_base).
#include <filesystem>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::io {

Trajectory parse_tum(const std::string& text, const std::string& source);
Trajectory read_tum(const std::filesystem::path& path);
void write_tum(const std::filesystem::path& path, const Trajectory& trajectory);

/// KITTI poses carry no stamps: `stamps` (one per line) or, when empty, the line index.
Trajectory parse_kitti_poses(const std::string& text, const std::string& source, const std::vector<double>& stamps = {});
Trajectory read_kitti_poses(const std::filesystem::path& path, const std::vector<double>& stamps = {});
void write_kitti_poses(const std::filesystem::path& path, const Trajectory& trajectory);

}  // namespace mlidar::io
