#pragma once
// Readers for the extrinsics files of OpenCalib (PJLab-ADG/SensorsCalibration),
// returned as mlidar Extrinsics so they feed calibration and SLAM directly.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "mlidar/io/extrinsics_io.hpp"

namespace mlidar::io {

/// lidar2lidar `initial_extrinsic.txt`: for each device a line `device_id: N`
/// followed by `(Roll,Pitch,Yaw,tx,ty,tz): r p y tx ty tz` (degrees, metres),
/// with p_ref = R p_device + t and R = Rz(yaw) Ry(pitch) Rx(roll). Device 0 is
/// the reference and becomes the base. `names[i]` names device i (default
/// "device_<i>"); the LiDARs come in file order.
Extrinsics parse_opencalib_initial_extrinsics(const std::string& text, const std::string& source,
                                              const std::vector<std::string>& names = {});
Extrinsics read_opencalib_initial_extrinsics(const std::filesystem::path& path, const std::vector<std::string>& names = {});

/// lidar2lidar `lidar_cloud_path.txt`: `device_id: N` then `path: P` per
/// device; P's file name is taken in `directory` (the paths name OpenCalib's
/// own layout). Returns device id -> cloud file.
std::map<int, std::filesystem::path> parse_opencalib_cloud_paths(const std::string& text, const std::string& source,
                                                                 const std::filesystem::path& directory);
/// The file in a scene folder; the clouds are looked up beside it.
std::map<int, std::filesystem::path> read_opencalib_cloud_paths(const std::filesystem::path& path);

/// OpenCalib JSON (`*-extrinsic.json`): top-level entries holding
/// `sensor_name`, `target_sensor_name` and `param.sensor_calib.data` (4x4,
/// p_target = T p_sensor). Every entry must share one target, which becomes
/// the base and the first LiDAR (identity); each sensor follows.
Extrinsics parse_opencalib_json(const std::string& text, const std::string& source);
Extrinsics read_opencalib_json(const std::filesystem::path& path);

}  // namespace mlidar::io
