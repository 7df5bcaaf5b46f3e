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
//   base: top                         # base frame name
//   times: times.txt                  # optional, default times.txt
//   lidars:
//     - name: top                     # [A-Za-z0-9_-]+, unique
//       model: RS-LiDAR-16            # model name
//       scans: scans/top              # folder relative to DIR (no "..")
//       vertical_angles_deg: [...]    # optional intrinsics
//       horizontal_resolution_deg: 0.2
//       min_range: 0.4
//       max_range: 150
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

namespace mlidar::io {

struct DatasetLidar {
  std::string name;
  LidarModel model;                      ///< name always; intrinsics when given
  std::filesystem::path scans;           ///< relative to the dataset folder
  std::optional<SE3> initial_extrinsic;  ///< T_base_lidar guess
};

struct DatasetGroundTruth {
  std::optional<std::filesystem::path> trajectory;
  std::optional<std::filesystem::path> extrinsics;
  std::optional<std::filesystem::path> boxes;
};

struct Dataset {
  std::string name;
  double frame_period = 0.1;
  std::string base = "base";
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
