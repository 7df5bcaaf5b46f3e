#include "mlidar/slam/frontend.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <tsl/robin_set.h>

#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {
namespace {

class StageTimer {
 public:
  StageTimer(StageSeconds& seconds, Stage stage) : seconds_(seconds), stage_(stage), start_(std::chrono::steady_clock::now()) {}
  ~StageTimer() {
    seconds_[static_cast<std::size_t>(stage_)] += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  StageSeconds& seconds_;
  Stage stage_;
  std::chrono::steady_clock::time_point start_;
};

/// Times shifted to the reference stamp (scan.time counts from scan.stamp), in a reused buffer.
std::span<const float> times_from_reference(const Scan& scan, double reference_stamp, std::vector<float>& buffer) {
  if (!scan.has_time()) return {};
  const float shift = static_cast<float>(scan.stamp - reference_stamp);
  if (shift == 0.0F) return scan.time;
  buffer.resize(scan.time.size());
  std::transform(scan.time.begin(), scan.time.end(), buffer.begin(), [shift](float t) { return t + shift; });
  return buffer;
}

void deskew_selection(const Scan& scan, std::span<const float> times, std::span<const std::uint32_t> indices, const LidarSetup& lidar,
                      const BodyVelocity& velocity, std::vector<Eigen::Vector3f>& out, std::vector<float>& out_times) {
  out.resize(indices.size());
  if (!indices.empty()) deskew_to_base(scan.points, times, indices, lidar.T_base_lidar, velocity, out);
  out_times.clear();
  if (!times.empty())
    for (const std::uint32_t i : indices) out_times.push_back(times[i]);
}

/// Where this scan's range-image rows come from: the LiDAR's model; without
/// one the scan's ring channel or rows recovered from its elevations
/// (held in ws.recovered); a null-rows model when neither (voxel fallback).
struct ScanRows {
  const LidarModel* model;
  std::span<const std::uint16_t> ring;
  RowSource source;
};

ScanRows scan_rows(const Scan& scan, const LidarSetup& lidar, const FrontEndConfig& config, FrontEndWorkspace& ws, StageSeconds& seconds) {
  ws.recovered.reset();
  if (!lidar.model.vertical_angles_deg.empty()) return {&lidar.model, scan.ring, RowSource::kModel};
  if (!config.recover_rows) return {&lidar.model, scan.ring, RowSource::kVoxelFallback};
  if (scan.has_ring()) {
    StageTimer timer(seconds, Stage::kRangeImage);
    ws.recovered = rows_from_ring_channel(scan.points, scan.ring, config.row_recovery);
  } else if (ws.recovery_skips_left > 0) {
    --ws.recovery_skips_left;
  } else {
    StageTimer timer(seconds, Stage::kRangeImage);
    ws.recovered = recover_rows(scan.points, config.row_recovery);
    const int skip = std::min(ws.recovery_next_skip, config.recover_rows_max_skip);
    ws.recovery_skips_left = ws.recovered ? 0 : skip;
    ws.recovery_next_skip = ws.recovered ? 1 : std::min(2 * skip, config.recover_rows_max_skip);
  }
  if (!ws.recovered) return {&lidar.model, scan.ring, RowSource::kVoxelFallback};
  ws.recovered->model.max_range = lidar.model.max_range;
  return {&ws.recovered->model, ws.recovered->ring, scan.has_ring() ? RowSource::kRingChannel : RowSource::kRecovered};
}

}  // namespace

const char* stage_name(Stage stage) {
  switch (stage) {
    case Stage::kRangeImage:
      return "range_image";
    case Stage::kSegmentation:
      return "segmentation";
    case Stage::kFeatures:
      return "features";
    case Stage::kDeskew:
      return "deskew";
    case Stage::kRegistration:
      return "registration";
    case Stage::kMapUpdate:
      return "map_update";
  }
  return "unknown";
}

const char* row_source_name(RowSource source) {
  switch (source) {
    case RowSource::kModel:
      return "model";
    case RowSource::kRingChannel:
      return "ring_channel";
    case RowSource::kRecovered:
      return "recovered";
    case RowSource::kVoxelFallback:
      return "voxel_fallback";
  }
  return "unknown";
}

std::vector<std::uint32_t> voxel_subsample(std::span<const Eigen::Vector3f> points, double voxel_m) {
  tsl::robin_set<VoxelKey, VoxelKeyHash> seen;
  std::vector<std::uint32_t> kept;
  const double inv = 1.0 / voxel_m;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    const VoxelKey key{static_cast<std::int32_t>(std::floor(p.x() * inv)), static_cast<std::int32_t>(std::floor(p.y() * inv)),
                       static_cast<std::int32_t>(std::floor(p.z() * inv))};
    if (seen.insert(key).second) kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

void run_front_end(const Scan& scan, double reference_stamp, const LidarSetup& lidar, const BodyVelocity& velocity,
                   const FrontEndConfig& config, FrontEndWorkspace& ws, LidarFeatures& out, StageSeconds& seconds) {
  std::vector<float> shifted;
  const std::span<const float> times = times_from_reference(scan, reference_stamp, shifted);
  const ScanRows rows = scan_rows(scan, lidar, config, ws, seconds);
  const LidarModel* model = rows.model;
  out.rows = static_cast<int>(model->rings());
  out.row_source = rows.source;
  if (model->vertical_angles_deg.empty()) {
    std::vector<std::uint32_t> kept;
    {
      StageTimer timer(seconds, Stage::kFeatures);
      kept = voxel_subsample(scan.points, config.fallback_voxel_m);
    }
    StageTimer timer(seconds, Stage::kDeskew);
    out.edges.clear();
    out.edge_times.clear();
    out.voxel_samples = kept.size();
    deskew_selection(scan, times, kept, lidar, velocity, out.planes, out.plane_times);
    return;
  }
  {
    StageTimer timer(seconds, Stage::kRangeImage);
    build_range_image(scan.points, rows.ring, *model, ws.image);
  }
  {
    StageTimer timer(seconds, Stage::kSegmentation);
    ws.sorted_angles_deg = model->vertical_angles_deg;
    std::sort(ws.sorted_angles_deg.begin(), ws.sorted_angles_deg.end());
    const Eigen::Vector3f up_lidar = (lidar.T_base_lidar.rotation().conjugate() * Vec3::UnitZ()).cast<float>();
    segment_range_image(ws.image, scan.points, ws.sorted_angles_deg, up_lidar, config.segmentation, ws.segmentation);
  }
  {
    StageTimer timer(seconds, Stage::kFeatures);
    extract_features(ws.image, ws.segmentation, config.features, ws.features, ws.indices);
    if (out.row_source == RowSource::kRecovered) {
      // The voxel samples too, so the map covers the scene as it does for the
      // LiDAR's scans that show no rows (whose samples fit poorly against a
      // map of range-image planes alone: BALM keyframes 0.15 m against 0.04 m).
      const std::vector<std::uint32_t> samples = voxel_subsample(scan.points, config.fallback_voxel_m);
      ws.indices.planes.insert(ws.indices.planes.end(), samples.begin(), samples.end());
      out.voxel_samples = samples.size();
    } else {
      out.voxel_samples = 0;
    }
  }
  StageTimer timer(seconds, Stage::kDeskew);
  deskew_selection(scan, times, ws.indices.edges, lidar, velocity, out.edges, out.edge_times);
  deskew_selection(scan, times, ws.indices.planes, lidar, velocity, out.planes, out.plane_times);
}

}  // namespace mlidar::slam
