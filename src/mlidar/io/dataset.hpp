#pragma once
// The dataset folder every command reads (the simulator writes exactly this):
//   DIR/dataset.yaml   this schema
//   DIR/times.txt      one frame stamp per line (seconds, strictly increasing)
//   DIR/scans/NAME/000000.pcd ...   one cloud per LiDAR per frame
//   DIR/groundtruth/{trajectory.tum, extrinsics.yaml, boxes/}   optional
//
// dataset.yaml (unknown keys are errors naming the key):
//   name: rv-campus-vehicle
//   frame_period: 0.1                 # seconds, > 0
//   base: top                         # the base frame: one of the lidars, or a frame that is
//                                     # none of them (e.g. the vehicle's); then
//   reference_lidar: top              # names the LiDAR that places it: its initial_extrinsic
//                                     # (required) is T_base_lidar, known; the jobs estimate in
//                                     # its frame and write their results in the base frame
//   times: times.txt                  # optional, default times.txt
//   lidars:
//     - name: top                     # [A-Za-z0-9_-]+, unique
//       model: RS-LiDAR-16            # model name
//       scans: scans/top              # folder relative to DIR (no "..")
//       vertical_angles_deg: [...]    # optional intrinsics, strictly increasing (ring order)
//       horizontal_resolution_deg: 0.2
//       min_range: 0.4
//       max_range: 150                # > min_range
//       range_noise_sigma: 0.03       # optional range 1-sigma (m), > 0; the SLAM's plane fit and point
//                                     # covariances take mapping.range_sigma_m without it
//       time_unit: ns                 # optional: s, ms, us or ns of the per-point time
//                                     # field (default from its type, io/point_table.hpp)
//       initial_extrinsic:            # optional T_base_lidar guess, p_base = R p_lidar + t
//         translation: [x, y, z]
//         quaternion_wxyz: [w, x, y, z]
//   groundtruth:                      # optional, paths relative to DIR
//     trajectory: groundtruth/trajectory.tum
//     extrinsics: groundtruth/extrinsics.yaml
//     boxes: groundtruth/boxes
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/io/point_table.hpp"

namespace mlidar::io {

struct DatasetLidar {
  std::string name;
  LidarModel model;                      ///< name always; intrinsics when given
  std::filesystem::path scans;           ///< relative to the dataset folder
  std::optional<SE3> initial_extrinsic;  ///< T_base_lidar guess
  TimeUnit time_unit = TimeUnit::kAuto;  ///< of its clouds' per-point time field
};

struct DatasetGroundTruth {
  std::optional<std::filesystem::path> trajectory;
  std::optional<std::filesystem::path> extrinsics;
  std::optional<std::filesystem::path> boxes;
};

struct Dataset {
  std::string name;
  double frame_period = 0.1;
  std::string base;             ///< the base frame: a LiDAR's name, or a frame that is no LiDAR (then reference_lidar)
  std::string reference_lidar;  ///< the LiDAR that places a base frame that is no LiDAR; empty when base is a LiDAR
  std::filesystem::path times = "times.txt";
  std::vector<DatasetLidar> lidars;
  DatasetGroundTruth groundtruth;
};

Dataset parse_dataset_yaml(const std::string& text, const std::string& source);
/// `path` is the dataset.yaml file or the dataset folder.
Dataset read_dataset_yaml(const std::filesystem::path& path);
std::string format_dataset_yaml(const Dataset& dataset);  ///< full double precision
void write_dataset_yaml(const std::filesystem::path& path, const Dataset& dataset);

/// times.txt: one stamp per line; blank lines and '#' comments skipped.
std::vector<double> parse_times(const std::string& text, const std::string& source);
std::vector<double> read_times(const std::filesystem::path& path);
void write_times(const std::filesystem::path& path, std::span<const double> stamps);

}  // namespace mlidar::io
