// Odometry hot paths on simulated rv/campus scans (seeded): each front-end
// stage on the top LiDAR, one scan-to-map registration, and whole frames with
// 1-4 of the rv rig's LiDARs (issue 7's scaling, thesis Table 4.7); the scan
// rows of real ring-less keyframes, and whole odometry over ten of them.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "mlidar/core/pose_uncertainty.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/rig.hpp"
#include "mlidar/sim/scenes.hpp"
#include "mlidar/sim/trajectory.hpp"
#include "mlidar/slam/odometry.hpp"
#include "mlidar/slam/row_recovery.hpp"

namespace mlidar::slam {
namespace {

constexpr int kFrames = 10;

/// kFrames frames of the rv rig driving through campus, all LiDARs.
struct Sequence {
  sim::SimRig rig = sim::named_rig("rv");
  std::vector<LidarSetup> lidars;
  std::vector<Frame> frames;
  std::vector<SE3> T_world_base;  ///< the true pose at each frame's stamp

  Sequence() {
    const auto trajectory = sim::SimTrajectory::named("vehicle", rig.base_height);
    std::vector<Vec3> path;
    for (int k = 0; k <= kFrames; ++k) path.push_back(trajectory.T_world_base(k * rig.frame_period()).translation());
    const sim::Scene scene = sim::make_scene("campus", 3, path);
    for (const auto& lidar : rig.lidars) lidars.push_back({lidar.name, lidar.model, lidar.T_base_lidar});
    for (int k = 0; k < kFrames; ++k) {
      Frame frame;
      frame.stamp = k * rig.frame_period();
      for (std::size_t i = 0; i < rig.lidars.size(); ++i)
        frame.scans.push_back(
            sim::simulate_sweep(scene, rig.lidars[i], trajectory, frame.stamp, sim::sweep_seed(3, static_cast<std::uint64_t>(k), i)).scan);
      T_world_base.push_back(trajectory.T_world_base(frame.stamp));
      frames.push_back(std::move(frame));
    }
  }
};

const Sequence& sequence() {
  static const Sequence data;  // simulated once per process
  return data;
}

void BM_RangeImage(benchmark::State& state) {
  const Sequence& data = sequence();
  const Scan& scan = data.frames[0].scans[0];
  RangeImage image;
  for (auto _ : state) {
    build_range_image(scan.points, scan.ring, data.lidars[0].model, image);
    benchmark::DoNotOptimize(image.index.data());
  }
  state.counters["points"] = static_cast<double>(scan.size());
}
BENCHMARK(BM_RangeImage)->Unit(benchmark::kMillisecond);

/// BALM's real Ouster keyframe `index` (shared data).
std::filesystem::path balm_keyframe_file(int index) {
  return std::filesystem::path(MLIDAR_SHARED_DATA) / "real" / "balm_ouster" / "frames" / ("full" + std::to_string(index) + ".pcd");
}

// Scan rows recovered from a real ring-less Ouster keyframe (BALM, ~75k
// points): arg = keyframe; 20 is a single sweep (64 rows recovered), 60 merged
// from sweeps taken while moving (refused after the same search).
void BM_RecoverRows(benchmark::State& state) {
  const std::filesystem::path file = balm_keyframe_file(static_cast<int>(state.range(0)));
  if (!std::filesystem::exists(file)) {
    state.SkipWithError("shared data not found");
    return;
  }
  const std::vector<Eigen::Vector3f> points = io::to_scan(io::read_cloud(file).table, file.string()).points;
  bool recovered = false;
  for (auto _ : state) {
    const auto rows = recover_rows(points);
    recovered = rows.has_value();
    benchmark::DoNotOptimize(rows);
  }
  state.counters["points"] = static_cast<double>(points.size());
  state.counters["recovered"] = recovered ? 1.0 : 0.0;
}
BENCHMARK(BM_RecoverRows)->Arg(20)->Arg(60)->Unit(benchmark::kMillisecond);

void BM_Segmentation(benchmark::State& state) {
  const Sequence& data = sequence();
  const Scan& scan = data.frames[0].scans[0];
  const LidarSetup& lidar = data.lidars[0];
  RangeImage image;
  build_range_image(scan.points, scan.ring, lidar.model, image);
  std::vector<double> angles = lidar.model.vertical_angles_deg;
  std::sort(angles.begin(), angles.end());
  const Eigen::Vector3f up = (lidar.T_base_lidar.rotation().conjugate() * Vec3::UnitZ()).cast<float>();
  Segmentation segmentation;
  for (auto _ : state) {
    segment_range_image(image, scan.points, angles, up, {}, segmentation);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Segmentation)->Unit(benchmark::kMillisecond);

void BM_Features(benchmark::State& state) {
  const Sequence& data = sequence();
  const Scan& scan = data.frames[0].scans[0];
  const LidarSetup& lidar = data.lidars[0];
  RangeImage image;
  build_range_image(scan.points, scan.ring, lidar.model, image);
  std::vector<double> angles = lidar.model.vertical_angles_deg;
  std::sort(angles.begin(), angles.end());
  Segmentation segmentation;
  segment_range_image(image, scan.points, angles, (lidar.T_base_lidar.rotation().conjugate() * Vec3::UnitZ()).cast<float>(), {},
                      segmentation);
  FeatureWorkspace workspace;
  FeatureIndices indices;
  for (auto _ : state) {
    extract_features(image, segmentation, {}, workspace, indices);
    benchmark::DoNotOptimize(indices.planes.data());
  }
  state.counters["edges"] = static_cast<double>(indices.edges.size());
  state.counters["planes"] = static_cast<double>(indices.planes.size());
}
BENCHMARK(BM_Features)->Unit(benchmark::kMillisecond);

void BM_DeskewAllPoints(benchmark::State& state) {
  const Sequence& data = sequence();
  const Scan& scan = data.frames[0].scans[0];
  BodyVelocity velocity;
  velocity.linear = Vec3(7.5, 0.0, 0.0);
  velocity.angular = Vec3(0.0, 0.0, 0.2);
  std::vector<Eigen::Vector3f> out(scan.size());
  for (auto _ : state) {
    deskew_to_base(scan.points, scan.time, {}, data.lidars[0].T_base_lidar, velocity, out);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_DeskewAllPoints)->Unit(benchmark::kMillisecond);

/// The features of all LiDARs of frame k (base frame, deskewed).
LidarFeatures frame_features(const Sequence& data, std::size_t k) {
  const OdometryConfig config;
  LidarFeatures all;
  for (std::size_t i = 0; i < data.lidars.size(); ++i) {
    FrontEndWorkspace ws;
    LidarFeatures one;
    StageSeconds seconds{};
    run_front_end(data.frames[k].scans[i], data.frames[k].stamp, data.lidars[i], {}, config.front_end, ws, one, seconds);
    all.edges.insert(all.edges.end(), one.edges.begin(), one.edges.end());
    all.planes.insert(all.planes.end(), one.planes.begin(), one.planes.end());
  }
  return all;
}

/// Frame 1's features of all LiDARs and the maps of frame 0's.
struct RegistrationCase {
  LidarFeatures features;
  VoxelMap edge_map{1.0, 10};
  VoxelMap plane_map{1.0, 20};
  SE3 guess{Quat::Identity(), Vec3(0.7, 0.0, 0.0)};  // ~0.1 m off the true 0.75 m step
};

const RegistrationCase& registration_case() {
  static const RegistrationCase built = [] {
    const Sequence& data = sequence();
    const OdometryConfig config;
    const LidarFeatures map_features = frame_features(data, 0);
    RegistrationCase out{frame_features(data, 1), VoxelMap(config.edge_voxel_m, config.edge_points_per_voxel),
                         VoxelMap(config.plane_voxel_m, config.plane_points_per_voxel)};
    out.edge_map.add(map_features.edges);
    out.plane_map.add(map_features.planes);
    return out;
  }();
  return built;
}

/// The map-neighbour search of scan-to-map registration: the last frame's plane features (all LiDARs, at the true
/// pose) against a plane map of the frames before (default voxel and bucket sizes, k = 5 within 1 m).
void BM_MapNearest(benchmark::State& state) {
  const Sequence& data = sequence();
  const OdometryConfig config;
  VoxelMap map(config.plane_voxel_m, config.plane_points_per_voxel);
  std::vector<Eigen::Vector3f> queries;
  for (std::size_t k = 0; k < data.frames.size(); ++k) {
    std::vector<Eigen::Vector3f> world = frame_features(data, k).planes;
    for (Eigen::Vector3f& p : world) p = (data.T_world_base[k] * Vec3(p.cast<double>())).cast<float>();
    if (k + 1 < data.frames.size())
      map.add(world);
    else
      queries = std::move(world);
  }
  std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors> near;
  std::size_t found = 0;
  for (auto _ : state) {
    found = 0;
    for (const Eigen::Vector3f& q : queries) found += static_cast<std::size_t>(map.nearest(q, config.registration.neighbors, 1.0F, near));
    benchmark::DoNotOptimize(near.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(queries.size()));  // queries per second
  state.counters["queries"] = static_cast<double>(queries.size());
  state.counters["found_per_query"] = static_cast<double>(found) / static_cast<double>(queries.size());
}
BENCHMARK(BM_MapNearest)->Unit(benchmark::kMillisecond);

/// Frame 1's features of all LiDARs registered to a map of frame 0's.
void BM_RegisterScanToMap(benchmark::State& state) {
  const RegistrationCase& c = registration_case();
  const OdometryConfig config;
  RegistrationResult result;
  for (auto _ : state) {
    result = register_scan_to_map(c.features.edges, c.features.planes, c.edge_map, c.plane_map, c.guess, 1.0, config.registration);
    benchmark::DoNotOptimize(result.T_world_base);
  }
  state.counters["iterations"] = result.iterations;
  state.counters["features"] = static_cast<double>(c.features.edges.size() + c.features.planes.size());
}
BENCHMARK(BM_RegisterScanToMap)->Unit(benchmark::kMillisecond);

/// The same registration on selected features (thesis Ch. 5): method (1 random,
/// 2 greedy), ratio in percent, epsilon in percent; counters say how many were
/// searched and chosen and the log det kept (Table 5.2's figure).
void BM_RegisterSelected(benchmark::State& state) {
  const RegistrationCase& c = registration_case();
  RegistrationConfig config = OdometryConfig{}.registration;
  config.selection.method = state.range(0) == 1 ? SelectionMethod::kRandom : SelectionMethod::kGreedy;
  config.selection.ratio = static_cast<double>(state.range(1)) / 100.0;
  config.selection.epsilon = static_cast<double>(state.range(2)) / 100.0;
  config.selection.adaptive = false;
  RegistrationResult result;
  for (auto _ : state) {
    result = register_scan_to_map(c.features.edges, c.features.planes, c.edge_map, c.plane_map, c.guess, 1.0, config);
    benchmark::DoNotOptimize(result.T_world_base);
  }
  const SelectionReport& report = *result.selection;
  state.counters["searched"] = static_cast<double>(report.screened);
  state.counters["chosen"] = static_cast<double>(report.chosen.size());
  state.counters["log_det"] = report.log_det_selected;
  state.counters["fell_back"] = report.fell_back ? 1.0 : 0.0;
  state.counters["selection_ms"] = report.seconds * 1e3;
}
BENCHMARK(BM_RegisterSelected)
    ->Args({1, 20, 80})
    ->Args({2, 20, 80})
    ->Args({2, 20, 50})
    ->Args({2, 20, 10})
    ->Args({2, 10, 80})
    ->Args({2, 50, 80})
    ->Unit(benchmark::kMillisecond);

/// kFrames whole frames (front ends, registration, map update) with the first N LiDARs per iteration; the second
/// argument 1: uncertainty-aware mapping (issue 19's speed criterion: <= +15 % per frame on 4 LiDARs).
void BM_OdometryFrame(benchmark::State& state) {
  const Sequence& data = sequence();
  const auto count = static_cast<std::size_t>(state.range(0));
  const std::vector<LidarSetup> lidars(data.lidars.begin(), data.lidars.begin() + static_cast<std::ptrdiff_t>(count));
  std::vector<Frame> frames = data.frames;
  for (auto& frame : frames) frame.scans.resize(count);
  OdometryConfig config;
  config.uncertainty.enabled = state.range(1) == 1;
  for (auto _ : state) {
    Odometry odometry(config, lidars);
    for (const Frame& frame : frames) benchmark::DoNotOptimize(odometry.process(frame).T_world_base);
  }
  state.SetItemsProcessed(state.iterations() * kFrames);  // items_per_second = frames per second
}
BENCHMARK(BM_OdometryFrame)->ArgsProduct({{1, 2, 3, 4}, {0}})->Args({4, 1})->Unit(benchmark::kMillisecond);

/// Eq 4.29 for 10k points of one LiDAR pose: the general H Theta H^T (arg 0) and the closed form per pose (arg 1).
void BM_PointCovariances(benchmark::State& state) {
  Mat6 covariance = Mat6::Identity() * 1e-4;
  covariance.bottomRightCorner<3, 3>() *= 0.01;
  const UncertainPose T_world_lidar{SE3::exp((Vec6() << 3.0, -1.0, 1.5, 0.1, -0.2, 0.8).finished()), covariance};
  std::vector<Vec3> points;
  for (int i = 0; i < 10000; ++i) points.emplace_back(20.0 * std::cos(0.01 * i), 20.0 * std::sin(0.01 * i), 0.001 * i - 2.0);
  const BeamPointCovariance closed_form(T_world_lidar, 0.03, 0.003);
  for (auto _ : state) {
    for (const Vec3& p : points) {
      if (state.range(0) == 0)
        benchmark::DoNotOptimize(point_covariance(T_world_lidar, p, lidar_point_noise(p, 0.03, 0.003)));
      else
        benchmark::DoNotOptimize(closed_form(p));
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}
BENCHMARK(BM_PointCovariances)->Arg(0)->Arg(1);

/// BALM keyframes 30..39 (0.5 s apart, taken while moving: voxel samples), read once; empty without the shared data.
const std::vector<Frame>& balm_keyframes() {
  static const std::vector<Frame> frames = [] {
    std::vector<Frame> out;
    for (int index = 30; index < 40; ++index) {
      const std::filesystem::path file = balm_keyframe_file(index);
      if (!std::filesystem::exists(file)) return std::vector<Frame>{};
      Frame frame;
      frame.stamp = 0.5 * (index - 30);
      frame.scans.push_back(io::to_scan(io::read_cloud(file).table, file.string()));
      frame.scans.back().stamp = frame.stamp;
      out.push_back(std::move(frame));
    }
    return out;
  }();
  return frames;
}

/// Odometry over ten real keyframes per iteration; arg = OdometryConfig::voxel_coarse_stride (1: every feature from
/// the prediction; 8, the default: a coarse pass on every 8th first).
void BM_RealKeyframes(benchmark::State& state) {
  const std::vector<Frame>& frames = balm_keyframes();
  if (frames.empty()) {
    state.SkipWithError("shared data not found");
    return;
  }
  OdometryConfig config;
  config.voxel_coarse_stride = static_cast<int>(state.range(0));
  for (auto _ : state) {
    Odometry odometry(config, {{"ouster", LidarModel{}, SE3::identity()}});
    for (const Frame& frame : frames) benchmark::DoNotOptimize(odometry.process(frame).T_world_base);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(frames.size()));  // keyframes per second
}
BENCHMARK(BM_RealKeyframes)->Arg(1)->Arg(8)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mlidar::slam
