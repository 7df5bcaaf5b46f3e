#pragma once
// KITTI formats: velodyne .bin scans (float32 x y z reflectance), label_2
// object files and calibration files (P0-P3, R0_rect, Tr_velo_to_cam, ...).
#include <array>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

/// A .bin of `floats_per_point` float32 values per point (4 for KITTI:
/// x y z reflectance; 5 for nuScenes: x y z intensity ring).
PointTable parse_kitti_bin(std::span<const std::byte> bytes, const std::string& source, int floats_per_point = 4);
PointTable read_kitti_bin(const std::filesystem::path& path, int floats_per_point = 4);
/// Writes x y z and intensity/reflectance (0 when absent) as float32.
void write_kitti_bin(const std::filesystem::path& path, const PointTable& table);

/// One line of a KITTI label_2 file (camera frame, metres, radians).
struct KittiObject {
  std::string type;  ///< Car, Pedestrian, Cyclist, DontCare, ...
  double truncated = 0.0;
  int occluded = 0;
  double alpha = 0.0;
  std::array<double, 4> bbox{};         ///< left top right bottom, pixels
  Eigen::Vector3d dimensions{0, 0, 0};  ///< height width length
  Eigen::Vector3d location{0, 0, 0};    ///< bottom centre in the camera frame
  double rotation_y = 0.0;
  std::optional<double> score;  ///< detections only
  int line = 0;                 ///< 1-based line it was read from (0: not read from text)
};

/// "line N column C (NAME)": how label errors name a field (column 0-based: 0 type ... 8-10 height width length,
/// 11-13 location, 14 rotation_y, 15 score).
std::string kitti_label_field(std::size_t line, std::size_t column);
std::vector<KittiObject> parse_kitti_labels(const std::string& text, const std::string& source);
std::vector<KittiObject> read_kitti_labels(const std::filesystem::path& path);
/// The label_2 lines of `objects` (exact numbers); OutputError naming `destination` for a type that is empty or
/// holds whitespace.
std::string format_kitti_labels(const std::vector<KittiObject>& objects, const std::string& destination);
void write_kitti_labels(const std::filesystem::path& path, const std::vector<KittiObject>& objects);

/// A KITTI calibration file: named matrices of 9 or 12 numbers.
struct KittiCalib {
  std::array<Eigen::Matrix<double, 3, 4>, 4> P{};  ///< P0..P3
  Eigen::Matrix3d R0_rect = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 4> Tr_velo_to_cam = Eigen::Matrix<double, 3, 4>::Zero();
  std::optional<Eigen::Matrix<double, 3, 4>> Tr_imu_to_velo;
};

KittiCalib parse_kitti_calib(const std::string& text, const std::string& source);
KittiCalib read_kitti_calib(const std::filesystem::path& path);
void write_kitti_calib(const std::filesystem::path& path, const KittiCalib& calib);

}  // namespace mlidar::io
