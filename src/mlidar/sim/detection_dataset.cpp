#include "mlidar/sim/detection_dataset.hpp"

#include <cstdio>
#include <map>

#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/detection_labels.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/detection_scene.hpp"
#include "mlidar/sim/ground_truth.hpp"

namespace mlidar::sim {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kTestSalt = 0x74657374'73706c74ULL;  // "testsplt"

std::string frame_name(int frame) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06d", frame);
  return name;
}

io::Dataset describe(const DetectionSpec& spec) {
  io::Dataset dataset;
  dataset.name = spec.rig.name + "-detection-" + detection_split_name(spec.split);
  dataset.frame_period = spec.rig.frame_period();
  dataset.base = spec.rig.base_frame;
  bool base_is_lidar = false;
  for (const auto& lidar : spec.rig.lidars) base_is_lidar = base_is_lidar || lidar.name == dataset.base;
  if (!base_is_lidar) dataset.reference_lidar = spec.rig.lidars.front().name;
  for (const auto& lidar : spec.rig.lidars)
    dataset.lidars.push_back({lidar.name, lidar.model, fs::path("scans") / lidar.name, lidar.T_base_lidar});
  dataset.groundtruth.extrinsics = "groundtruth/extrinsics.yaml";
  dataset.groundtruth.boxes = "groundtruth/label_2";
  return dataset;
}

/// Points of each labelled object, per LiDAR (object id -> LiDAR index -> count).
using PointCounts = std::map<int, std::vector<int>>;

nlohmann::json object_json(const LabelledObject& object, const io::KittiObject& box, const std::vector<int>& points, const SimRig& rig) {
  nlohmann::json per_lidar = nlohmann::json::object();
  int total = 0;
  for (std::size_t i = 0; i < rig.lidars.size(); ++i) {
    per_lidar[rig.lidars[i].name] = points[i];
    total += points[i];
  }
  const double distance = box.location.head<2>().norm();
  return {{"id", object.id},
          {"class", io::object_class_name(io::object_class_from_name(object.type).value())},
          {"box",
           {{"center_bottom", {box.location.x(), box.location.y(), box.location.z()}},
            {"size_lwh", {box.dimensions.z(), box.dimensions.y(), box.dimensions.x()}},
            {"yaw", box.rotation_y}}},
          {"points", per_lidar},
          {"points_total", total},
          {"has_points", total > 0},
          {"distance_m", distance},
          {"difficulty", detection_difficulty(distance)}};
}

/// Writes one frame's label_2 and JSON; adds its objects to the per-class and per-difficulty tallies.
/// Objects per class ("car", ...) and per difficulty or "no_points".
using Tally = std::map<std::string, std::map<std::string, int>>;

void write_labels(const fs::path& dir, int frame, const Scene& scene, const SE3& T_world_base, const PointCounts& counts, const SimRig& rig,
                  Tally& tally) {
  std::vector<io::KittiObject> boxes;
  nlohmann::json objects = nlohmann::json::array();
  const std::vector<int> none(rig.lidars.size(), 0);
  for (const auto& object : scene.objects()) {
    const io::KittiObject box = box_in_base(object, 0.0, T_world_base);
    if (box.location.head<2>().norm() > 70.0) continue;
    const auto found = counts.find(object.id);
    nlohmann::json entry = object_json(object, box, found == counts.end() ? none : found->second, rig);
    ++tally[entry["class"]][entry["has_points"].get<bool>() ? entry["difficulty"].get<std::string>() : "no_points"];
    objects.push_back(std::move(entry));
    boxes.push_back(box);
  }
  const std::string name = frame_name(frame);
  io::write_kitti_labels(dir / "label_2" / (name + ".txt"), boxes);
  const nlohmann::json labels = {{"frame", name}, {"objects", objects}};
  io::write_atomically(dir / "labels" / (name + ".json"), [&](std::ostream& out) { out << labels.dump(1) << '\n'; });
}

}  // namespace

DetectionSplit detection_split_from_name(const std::string& name) {
  if (name == "train") return DetectionSplit::kTrain;
  if (name == "test") return DetectionSplit::kTest;
  throw UsageError("unknown split '" + name + "' (known: train, test)");
}

std::string detection_split_name(DetectionSplit split) { return split == DetectionSplit::kTrain ? "train" : "test"; }

std::string detection_difficulty(double distance_m) {
  if (distance_m < 20.0) return "easy";
  if (distance_m < 30.0) return "moderate";
  if (distance_m < 50.0) return "hard";
  return "beyond";
}

DetectionLayout detection_layout_from_name(const std::string& name) {
  if (name == "street") return DetectionLayout::kStreet;
  if (name == "cars") return DetectionLayout::kCars;
  throw UsageError("--scene: unknown scene '" + name + "' (street or cars)");
}

std::string detection_layout_name(DetectionLayout layout) { return layout == DetectionLayout::kCars ? "cars" : "street"; }

std::uint64_t detection_scene_seed(std::uint64_t seed, DetectionSplit split, int frame) {
  return sweep_seed(split == DetectionSplit::kTest ? seed ^ kTestSalt : seed, static_cast<std::uint64_t>(frame), 0xffffULL);
}

void write_detection_dataset(const DetectionSpec& spec, const fs::path& out, const ProgressFn& progress) {
  if (spec.frames <= 0) throw UsageError("--frames must be at least 1");
  if (spec.rig.lidars.empty()) throw UsageError("the rig has no LiDAR");
  for (const auto& lidar : spec.rig.lidars) fs::create_directories(out / "scans" / lidar.name);
  fs::create_directories(out / "groundtruth" / "label_2");
  fs::create_directories(out / "groundtruth" / "labels");
  const double period = spec.rig.frame_period();
  // The vehicle stands still at the origin, its base frame rig.base_height above the ground.
  const SE3 T_world_base(Quat::Identity(), Vec3(0.0, 0.0, spec.rig.base_height));
  const SimTrajectory standing = SimTrajectory::stationary(T_world_base);
  Tally tally;
  std::vector<double> stamps;
  for (int frame = 0; frame < spec.frames; ++frame) {
    const std::uint64_t scene_seed = detection_scene_seed(spec.seed, spec.split, frame);
    const Scene scene = spec.layout == DetectionLayout::kCars ? cars_scene(scene_seed) : detection_scene(scene_seed);
    PointCounts counts;
    for (std::size_t i = 0; i < spec.rig.lidars.size(); ++i) {
      const SimLidar& lidar = spec.rig.lidars[i];
      const SimulatedScan sweep = simulate_sweep(scene, lidar, standing, 0.0, sweep_seed(scene_seed, 0, i));
      for (const int id : sweep.object_id) {
        if (id <= 0) continue;
        auto& per_lidar = counts[id];
        per_lidar.resize(spec.rig.lidars.size(), 0);
        ++per_lidar[i];
      }
      io::PcdCloud cloud;
      cloud.encoding = spec.encoding;
      cloud.table = io::from_scan(sweep.scan);
      io::write_pcd(out / "scans" / lidar.name / (frame_name(frame) + ".pcd"), cloud);
    }
    write_labels(out / "groundtruth", frame, scene, T_world_base, counts, spec.rig, tally);
    stamps.push_back(period * frame);
    if (progress) progress(frame + 1, spec.frames);
  }
  io::Extrinsics truth;
  truth.base = spec.rig.base_frame;
  for (const auto& lidar : spec.rig.lidars) truth.lidars.push_back({lidar.name, lidar.T_base_lidar, std::nullopt});
  io::write_extrinsics(out / "groundtruth" / "extrinsics.yaml", truth);
  const nlohmann::json summary = {{"split", detection_split_name(spec.split)},
                                  {"seed", spec.seed},
                                  {"rig", spec.rig.name},
                                  {"scene", detection_layout_name(spec.layout)},
                                  {"frames", spec.frames},
                                  {"objects", tally},
                                  {"difficulty_max_m", {{"easy", 20.0}, {"moderate", 30.0}, {"hard", 50.0}}}};
  io::write_atomically(out / "groundtruth" / "detection.json", [&](std::ostream& o) { o << summary.dump(1) << '\n'; });
  io::write_times(out / "times.txt", stamps);
  io::write_dataset_yaml(out / "dataset.yaml", describe(spec));
}

}  // namespace mlidar::sim
