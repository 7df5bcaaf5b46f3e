#include "mlidar/pipelines/odometry_job.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {
namespace {

/// One input source: the LiDARs and, per frame, one cloud file per LiDAR.
struct Inputs {
  std::vector<slam::LidarSetup> lidars;
  std::vector<double> stamps;
  std::vector<std::vector<std::filesystem::path>> files;  ///< [frame][lidar]
};

Inputs dataset_inputs(const OdometryJob& job) {
  const io::Dataset dataset = io::read_dataset_yaml(job.dataset);
  Inputs in;
  in.stamps = io::read_times(job.dataset / dataset.times);
  std::vector<std::vector<std::filesystem::path>> per_lidar;
  for (const auto& lidar : dataset.lidars) {
    if (!job.lidars.empty() && std::find(job.lidars.begin(), job.lidars.end(), lidar.name) == job.lidars.end()) continue;
    in.lidars.push_back({lidar.name, lidar.model, lidar.initial_extrinsic.value_or(SE3::identity())});
    per_lidar.push_back(natural_sorted_clouds(job.dataset / lidar.scans));
    if (per_lidar.back().size() < in.stamps.size())
      throw InputError((job.dataset / lidar.scans).string(), "scans", "has " + std::to_string(per_lidar.back().size()) + " clouds for " +
                                                                          std::to_string(in.stamps.size()) + " stamps in times.txt");
  }
  for (const auto& name : job.lidars)
    if (std::none_of(in.lidars.begin(), in.lidars.end(), [&](const auto& l) { return l.name == name; }))
      throw UsageError("--lidars: no LiDAR '" + name + "' in " + (job.dataset / "dataset.yaml").string());
  in.files.resize(in.stamps.size());
  for (std::size_t k = 0; k < in.stamps.size(); ++k)
    for (const auto& clouds : per_lidar) in.files[k].push_back(clouds[k]);
  return in;
}

Inputs scan_folder_inputs(const OdometryJob& job) {
  Inputs in;
  in.lidars.push_back({"lidar", LidarModel{}, SE3::identity()});
  const auto clouds = natural_sorted_clouds(job.scans);
  for (std::size_t k = 0; k < clouds.size(); ++k) {
    in.stamps.push_back(static_cast<double>(k) * job.period);
    in.files.push_back({clouds[k]});
  }
  return in;
}

}  // namespace

Scan load_dataset_scan(const std::filesystem::path& path, double frame_stamp) {
  const io::CloudFile cloud = io::read_cloud(path);
  Scan scan = io::to_scan(cloud.table, path.string());
  scan.stamp = frame_stamp;
  if (const auto* t = cloud.table.find("t"); t != nullptr && scan.has_time() && cloud.table.num_points > 0) {
    double earliest = t->value(0);
    for (std::size_t i = 1; i < cloud.table.num_points; ++i) earliest = std::min(earliest, t->value(i));
    if (std::abs(earliest) < 1.0) scan.stamp = frame_stamp + earliest;  // relative times: sweep start after the stamp
  }
  return scan;
}

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) != 0 && std::isdigit(static_cast<unsigned char>(b[j])) != 0) {
      std::size_t i_end = i, j_end = j;
      while (i_end < a.size() && std::isdigit(static_cast<unsigned char>(a[i_end])) != 0) ++i_end;
      while (j_end < b.size() && std::isdigit(static_cast<unsigned char>(b[j_end])) != 0) ++j_end;
      std::string_view da(a.data() + i, i_end - i), db(b.data() + j, j_end - j);
      while (da.size() > 1 && da.front() == '0') da.remove_prefix(1);
      while (db.size() > 1 && db.front() == '0') db.remove_prefix(1);
      if (da.size() != db.size()) return da.size() < db.size();
      if (da != db) return da < db;
      i = i_end;
      j = j_end;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

std::vector<std::filesystem::path> natural_sorted_clouds(const std::filesystem::path& folder) {
  if (!std::filesystem::is_directory(folder)) throw InputError(folder.string(), "folder", "is not a folder of point clouds");
  std::vector<std::filesystem::path> clouds;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".pcd" || ext == ".ply" || ext == ".bin") clouds.push_back(entry.path());
  }
  std::sort(clouds.begin(), clouds.end(), [](const auto& a, const auto& b) { return natural_less(a.filename().string(), b.filename().string()); });
  if (clouds.empty()) throw InputError(folder.string(), "folder", "holds no .pcd, .ply or .bin clouds");
  return clouds;
}

std::vector<std::optional<std::filesystem::path>> frame_clouds(const std::filesystem::path& folder, std::size_t frames) {
  const std::vector<std::filesystem::path> clouds = natural_sorted_clouds(folder);
  std::vector<std::optional<std::filesystem::path>> by_frame(frames);
  if (clouds.size() >= frames) {
    std::copy_n(clouds.begin(), frames, by_frame.begin());
    return by_frame;
  }
  for (const auto& cloud : clouds) {
    const std::string stem = cloud.stem().string();
    const bool digits = !stem.empty() && stem.size() <= 9 && std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
    const std::size_t k = digits ? static_cast<std::size_t>(std::stoul(stem)) : frames;
    if (k >= frames)
      throw InputError(cloud.string(), "file name", "has " + std::to_string(clouds.size()) + " clouds for " + std::to_string(frames) +
                                                        " stamps: with scans missing, each file must be named by its frame number (0 to " +
                                                        std::to_string(frames - 1) + "), e.g. 000123.pcd");
    if (by_frame[k]) throw InputError(cloud.string(), "file name", "names frame " + std::to_string(k) + " like " + by_frame[k]->string());
    by_frame[k] = cloud;
  }
  return by_frame;
}

OdometryJobSummary run_odometry_job(const OdometryJob& job, const std::function<void(int, int)>& progress) {
  if (job.dataset.empty() == job.scans.empty()) throw UsageError("give exactly one of --dataset DIR or --scans FOLDER");
  if (!(job.period > 0.0)) throw UsageError("--period must be > 0 seconds");
  if (job.threads < 0) throw UsageError("--threads must be >= 0");
  if (!job.scans.empty() && !job.lidars.empty()) throw UsageError("--lidars applies to --dataset only");
  const Inputs in = job.dataset.empty() ? scan_folder_inputs(job) : dataset_inputs(job);
  std::unique_ptr<tbb::global_control> threads;
  if (job.threads > 0) threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(job.threads));
  std::filesystem::create_directories(job.out);

  slam::Odometry odometry({}, in.lidars);
  std::vector<slam::FrameResult> results;
  OdometryJobSummary summary;
  for (std::size_t k = 0; k < in.stamps.size(); ++k) {
    Frame frame;
    frame.stamp = in.stamps[k];
    for (const auto& file : in.files[k]) frame.scans.push_back(load_dataset_scan(file, frame.stamp));
    results.push_back(odometry.process(frame));
    summary.trajectory.poses.push_back({frame.stamp, results.back().T_world_base});
    if (progress) progress(static_cast<int>(k + 1), static_cast<int>(in.stamps.size()));
  }
  summary.frames = results.size();
  for (const auto& r : results) {
    summary.degenerate_frames += r.registration.degenerate ? 1 : 0;
    summary.lost_frames += r.lost ? 1 : 0;
    for (const double s : r.seconds) summary.mean_frame_seconds += s / static_cast<double>(results.size());
  }
  io::write_tum(job.out / "trajectory.tum", summary.trajectory);
  io::write_kitti_poses(job.out / "trajectory.kitti", summary.trajectory);
  write_map_ply(job.out / "map.ply", odometry);
  const std::string metrics = odometry_metrics_json(results, in.lidars).dump(2);
  io::write_atomically(job.out / "metrics.json", [&](std::ostream& out) { out << metrics << '\n'; });
  return summary;
}

}  // namespace mlidar::pipelines
