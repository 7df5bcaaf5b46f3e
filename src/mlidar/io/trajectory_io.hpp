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

/// BALM's pose CSV (hku-mars/BALM benchmark_realworld): four lines `a,b,c,d,`
/// per pose holding a 4x4 T_world_lidar whose bottom-right element is the
/// stamp (unix seconds) instead of 1.
Trajectory parse_balm_poses(const std::string& text, const std::string& source);
Trajectory read_balm_poses(const std::filesystem::path& path);

/// One 4x4 homogeneous matrix as 16 whitespace-separated numbers, row-major
/// (bottom row 0 0 0 1); the rotation is re-orthonormalised, and rejected
/// when further than 1e-3 from orthonormal.
SE3 parse_matrix_transform(const std::string& text, const std::string& source);
SE3 read_matrix_transform(const std::filesystem::path& path);

}  // namespace mlidar::io
