#pragma once
// `mlidar simulate detection`: labelled multi-LiDAR street scenes for 3D
// object detection (thesis 6.6.1.1 uses Lyft's three LiDARs). Each frame is a
// scene of its own (sim/detection_scene.hpp) seen from the standing vehicle.
// The folder is a dataset (io/dataset.hpp) plus labels:
//   dataset.yaml, times.txt, scans/NAME/NNNNNN.pcd      as `simulate drive` writes them
//   groundtruth/extrinsics.yaml                          the true T_base_lidar
//   groundtruth/label_2/NNNNNN.txt   every object within 70 m, KITTI label_2 layout in the BASE frame
//                                    (conventions in sim/ground_truth.hpp; class Car, Pedestrian, Cyclist)
//   groundtruth/labels/NNNNNN.json   the same objects in the same order: {"frame", "objects": [{"id", "class"
//                                    (car|pedestrian|cyclist), "box": {"center_bottom": [x,y,z], "size_lwh":
//                                    [l,w,h], "yaw"}, "points": {LIDAR: n}, "points_total", "has_points",
//                                    "distance_m" (horizontal, from the base origin), "difficulty"}]}
//   groundtruth/detection.json       split, seed, rig, frames, objects per class and difficulty
// Difficulty by distance (thesis 6.6.1.2): easy < 20 m, moderate < 30 m, hard < 50 m, else beyond.
// An object no LiDAR hit is kept, with has_points false. Train and test draw each frame's scene and noise
// from seeds mixed with the split's name, so the two splits never share a scene; the same spec gives the
// same bytes.
#include <cstdint>
#include <filesystem>
#include <string>

#include "mlidar/io/pcd.hpp"
#include "mlidar/sim/drive_dataset.hpp"
#include "mlidar/sim/rig.hpp"

namespace mlidar::sim {

enum class DetectionSplit : std::uint8_t { kTrain, kTest };
/// street: detection_scene's streets (the default); cars: cars_scene's few cars on open ground (quick tests).
enum class DetectionLayout : std::uint8_t { kStreet, kCars };

struct DetectionSpec {
  SimRig rig;
  int frames = 100;
  std::uint64_t seed = 1;
  DetectionSplit split = DetectionSplit::kTrain;
  DetectionLayout layout = DetectionLayout::kStreet;
  io::PcdEncoding encoding = io::PcdEncoding::kBinary;
};

/// "train" / "test"; UsageError otherwise.
DetectionSplit detection_split_from_name(const std::string& name);
std::string detection_split_name(DetectionSplit split);
/// "street" / "cars"; UsageError otherwise.
DetectionLayout detection_layout_from_name(const std::string& name);
std::string detection_layout_name(DetectionLayout layout);

/// The difficulty of an object at horizontal distance distance_m: "easy", "moderate", "hard" or "beyond".
std::string detection_difficulty(double distance_m);

/// The seed of frame `frame`'s scene in a split (SplitMix64 of seed, split and frame).
std::uint64_t detection_scene_seed(std::uint64_t seed, DetectionSplit split, int frame);

/// Writes the folder `out` (new or empty; the CLI gives a RunFolder's staging folder). UsageError for zero frames
/// or an empty rig, before anything is written.
void write_detection_dataset(const DetectionSpec& spec, const std::filesystem::path& out, const ProgressFn& progress = {});

}  // namespace mlidar::sim
