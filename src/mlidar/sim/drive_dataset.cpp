#include "mlidar/sim/drive_dataset.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <optional>
#include <random>
#include <set>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/surface_samples.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/ground_truth.hpp"
#include "mlidar/sim/scenes.hpp"
#include "mlidar/sim/surface_sampler.hpp"

namespace mlidar::sim {
namespace {

namespace fs = std::filesystem;

std::string frame_file(int frame, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d%s", frame, extension);
  return name;
}

Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  // Draws in statements of their own, last argument first (scene_layout.hpp: uniform).
  const auto draw = [&] {
    const double z = normal(rng), y = normal(rng);
    return Vec3(normal(rng), y, z);
  };
  Vec3 v = draw();
  while (v.norm() < 1e-9) v = draw();
  return v.normalized();
}

io::Dataset describe(const DriveSpec& spec) {
  io::Dataset dataset;
  dataset.name = spec.rig.name + "-" + spec.scene;
  dataset.frame_period = spec.rig.frame_period();
  dataset.base = spec.rig.base_frame;
  // A base frame that is no LiDAR (lyft's vehicle) is placed by the first LiDAR, whose extrinsic is given exactly.
  const bool base_is_lidar =
      std::any_of(spec.rig.lidars.begin(), spec.rig.lidars.end(), [&](const auto& l) { return l.name == dataset.base; });
  if (!base_is_lidar) dataset.reference_lidar = spec.rig.lidars.front().name;
  std::mt19937_64 rng(spec.seed ^ 0x7065727475726221ULL);
  for (const auto& lidar : spec.rig.lidars) {
    io::DatasetLidar entry{lidar.name, lidar.model, fs::path("scans") / lidar.name, lidar.T_base_lidar};
    const bool is_base = lidar.T_base_lidar.log().isZero(0.0);
    if (!is_base && lidar.name != dataset.reference_lidar) {
      const Vec6 xi =
          (Vec6() << spec.perturb_m * random_unit(rng), spec.perturb_deg * std::numbers::pi / 180.0 * random_unit(rng)).finished();
      entry.initial_extrinsic = lidar.T_base_lidar * SE3::exp(xi);
    }
    dataset.lidars.push_back(entry);
  }
  dataset.groundtruth.trajectory = "groundtruth/trajectory.tum";
  dataset.groundtruth.extrinsics = "groundtruth/extrinsics.yaml";
  return dataset;
}

io::Extrinsics true_extrinsics(const SimRig& rig) {
  io::Extrinsics extrinsics;
  extrinsics.base = rig.base_frame;
  for (const auto& lidar : rig.lidars) extrinsics.lidars.push_back({lidar.name, lidar.T_base_lidar, std::nullopt});
  return extrinsics;
}

void write_boxes(const fs::path& dir, int frame, const Scene& scene, const std::set<int>& seen, double stamp, const SE3& T_world_base) {
  std::vector<io::KittiObject> boxes;
  std::string ids;
  for (const int id : seen) {
    boxes.push_back(box_in_base(scene.objects()[static_cast<std::size_t>(id - 1)], stamp, T_world_base));
    ids += std::to_string(id) + "\n";
  }
  io::write_kitti_labels(dir / frame_file(frame, ".txt"), boxes);
  io::write_atomically(dir / frame_file(frame, ".ids"), [&](std::ostream& out) { out << ids; });
}

}  // namespace

void write_drive_dataset(const DriveSpec& spec, const fs::path& out, const ProgressFn& progress) {
  if (spec.frames <= 0) throw UsageError("--frames must be at least 1");
  if (spec.rig.lidars.empty()) throw UsageError("the rig has no LiDAR");
  const double period = spec.rig.frame_period();
  const double start = spec.trajectory.start_time();
  const double last_stamp = start + period * (spec.frames - 1);
  if (last_stamp + period > spec.trajectory.end_time() + 1e-9) {
    const int fit = static_cast<int>(std::floor((spec.trajectory.end_time() - start) / period + 1e-9));
    throw UsageError("the trajectory covers " + std::to_string(spec.trajectory.end_time() - start) + " s: at most " +
                     std::to_string(std::max(0, fit)) + " frames of " + std::to_string(period) + " s");
  }
  std::vector<Vec3> path;
  for (int k = 0; k <= spec.frames; ++k) path.push_back(spec.trajectory.T_world_base(start + k * period).translation());
  const Scene scene = make_scene(spec.scene, spec.seed, path);

  const fs::path& dir = out;
  for (const auto& lidar : spec.rig.lidars) fs::create_directories(dir / "scans" / lidar.name);
  fs::create_directories(dir / "groundtruth");
  io::Dataset dataset = describe(spec);
  const bool has_boxes = !scene.objects().empty();
  if (has_boxes) {
    fs::create_directories(dir / "groundtruth" / "boxes");
    dataset.groundtruth.boxes = "groundtruth/boxes";
  }

  Trajectory truth;
  std::vector<double> stamps;
  std::optional<SurfaceSampler> surfaces;
  if (spec.surface_spacing_m > 0.0) surfaces.emplace(spec.surface_spacing_m, spec.trajectory.T_world_base(start).inverse());
  for (int frame = 0; frame < spec.frames; ++frame) {
    const double stamp = start + period * frame;
    std::set<int> seen;
    for (std::size_t i = 0; i < spec.rig.lidars.size(); ++i) {
      const SimLidar& lidar = spec.rig.lidars[i];
      const auto sweep = simulate_sweep(scene, lidar, spec.trajectory, stamp, sweep_seed(spec.seed, static_cast<std::uint64_t>(frame), i));
      if (surfaces)
        for (std::size_t k = 0; k < sweep.scenery_hits.size(); ++k) surfaces->add(sweep.scenery_hits[k], sweep.scenery_normals[k]);
      for (const int id : sweep.object_id) {
        if (id > 0) seen.insert(id);
      }
      io::PcdCloud cloud;
      cloud.encoding = spec.encoding;
      cloud.table = io::from_scan(sweep.scan);
      io::write_pcd(dir / "scans" / lidar.name / frame_file(frame, ".pcd"), cloud);
    }
    const SE3 T_world_base = spec.trajectory.T_world_base(stamp);
    if (has_boxes) write_boxes(dir / "groundtruth" / "boxes", frame, scene, seen, stamp, T_world_base);
    truth.poses.push_back({stamp, T_world_base});
    stamps.push_back(stamp);
    if (progress) progress(frame + 1, spec.frames);
  }
  io::write_tum(dir / "groundtruth" / "trajectory.tum", truth);
  if (surfaces) io::write_surface_samples(dir / "groundtruth" / "surfaces.ply", surfaces->samples());
  io::write_extrinsics(dir / "groundtruth" / "extrinsics.yaml", true_extrinsics(spec.rig));
  io::write_times(dir / "times.txt", stamps);
  io::write_dataset_yaml(dir / "dataset.yaml", dataset);
}

}  // namespace mlidar::sim
