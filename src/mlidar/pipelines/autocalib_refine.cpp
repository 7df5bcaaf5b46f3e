#include "mlidar/pipelines/autocalib_refine.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mlidar/core/error.hpp"
#include "mlidar/pipelines/odometry_job.hpp"
#include "mlidar/slam/deskew.hpp"
#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::pipelines {
namespace {

/// Sigma of a zero-mean Gaussian from its mean absolute value: E|r| = sigma sqrt(2 / pi).
double residual_variance(double mean_abs_residual) {
  const double sigma = mean_abs_residual * std::sqrt(std::numbers::pi / 2.0);
  return sigma * sigma;
}

std::vector<Eigen::Vector3f> subsampled(const Scan& scan, const SE3& T, double voxel_m) {
  std::vector<Eigen::Vector3f> out;
  for (const std::uint32_t i : slam::voxel_subsample(scan.points, voxel_m)) out.push_back(T * scan.points[i]);
  return out;
}

void move_all(std::vector<Eigen::Vector3f>& points, const SE3& T) {
  for (auto& p : points) p = T * p;
}

/// The target's features at frame k in its own frame at the stamp, deskewed with
/// the base velocity carried to the target by X0 (T_rel_target = X0^-1 T_rel_base X0).
slam::LidarFeatures target_features(const BaseLocalMaps& base, const LidarFrames& target, const Scan& scan, std::size_t k,
                                    const SE3& X0, const RefineConfig& config) {
  const slam::BodyVelocity v_base = base.velocity(k);
  constexpr double kDt = 0.1;  // any positive interval: the velocity is what is carried
  const SE3 T_rel_target = X0.inverse() * v_base.pose_at(kDt) * X0;
  const slam::LidarSetup setup{target.name, target.model, SE3::identity()};
  slam::FrontEndWorkspace workspace;
  slam::LidarFeatures features;
  slam::StageSeconds seconds{};
  slam::run_front_end(scan, base.trajectory().stamps[k], setup, slam::BodyVelocity::from_relative_pose(T_rel_target, kDt),
                      config.front_end, workspace, features, seconds);
  return features;
}

/// Step 3: coarse then fine registration from T_world_base_k X0.
std::optional<calib::ExtrinsicCandidate> register_frame(const slam::LidarFeatures& features, const SE3& T_world_base,
                                                        const SE3& X0, std::size_t k,
                                                        const std::pair<slam::VoxelMap, slam::VoxelMap>& maps,
                                                        const RefineConfig& config) {
  const auto& [edge_map, plane_map] = maps;
  const slam::RegistrationResult coarse =
      slam::register_scan_to_map(features.edges, features.planes, edge_map, plane_map, T_world_base * X0,
                                 config.coarse_correspondence_m, config.registration);
  const slam::RegistrationResult fine =
      slam::register_scan_to_map(features.edges, features.planes, edge_map, plane_map, coarse.T_world_base,
                                 config.fine_correspondence_m, config.registration);
  if (fine.degenerate || fine.match_ratio() < config.min_match_ratio) return std::nullopt;
  calib::ExtrinsicCandidate candidate;
  candidate.frame = k;
  candidate.T_base_target = T_world_base.inverse() * fine.T_world_base;
  candidate.error_m = fine.mean_residual_m;
  candidate.information = calib::extrinsic_information(fine.hessian, residual_variance(fine.mean_residual_m),
                                                       T_world_base, candidate.T_base_target);
  return candidate;
}

}  // namespace

const char* to_string(RefineVerdict verdict) {
  switch (verdict) {
    case RefineVerdict::ok: return "ok";
    case RefineVerdict::no_overlap: return "no_overlap";
    case RefineVerdict::too_few_candidates: return "too_few_candidates";
  }
  return "unknown";
}

BaseLocalMaps::BaseLocalMaps(LidarFrames base, BaseTrajectory trajectory, RefineConfig config)
    : base_(std::move(base)), trajectory_(std::move(trajectory)), config_(std::move(config)) {
  const std::size_t frames = trajectory_.stamps.size();
  if (base_.clouds.size() < frames)
    throw InputError(base_.folder.string(), "scans", "has " + std::to_string(base_.clouds.size()) + " clouds for " +
                                              std::to_string(frames) + " stamps");
  world_features_.resize(frames);
  overlap_points_.resize(frames);
}

slam::BodyVelocity BaseLocalMaps::velocity(std::size_t k) const {
  const auto& T = trajectory_.T_world_base;
  const auto& lost = trajectory_.lost;
  const auto between = [&](std::size_t a, std::size_t b) {
    return slam::BodyVelocity::from_relative_pose(T[a].inverse() * T[b], trajectory_.stamps[b] - trajectory_.stamps[a]);
  };
  if (k + 1 < T.size() && !lost[k] && !lost[k + 1]) return between(k, k + 1);
  if (k > 0 && !lost[k] && !lost[k - 1]) return between(k - 1, k);
  return {};
}

const std::vector<Eigen::Vector3f>& BaseLocalMaps::overlap_points(std::size_t k) {
  if (!overlap_points_[k]) {
    const Scan scan = load_dataset_scan(base_.clouds[k], trajectory_.stamps[k]);
    overlap_points_[k] = subsampled(scan, SE3::identity(), config_.overlap_voxel_m);
  }
  return *overlap_points_[k];
}

const slam::LidarFeatures& BaseLocalMaps::world_features(std::size_t j) {
  if (!world_features_[j]) {
    const Scan scan = load_dataset_scan(base_.clouds[j], trajectory_.stamps[j]);
    const slam::LidarSetup setup{base_.name, base_.model, SE3::identity()};
    slam::LidarFeatures features;
    slam::StageSeconds seconds{};
    slam::run_front_end(scan, trajectory_.stamps[j], setup, velocity(j), config_.front_end, workspace_, features, seconds);
    move_all(features.edges, trajectory_.T_world_base[j]);
    move_all(features.planes, trajectory_.T_world_base[j]);
    world_features_[j] = std::move(features);
  }
  return *world_features_[j];
}

std::pair<slam::VoxelMap, slam::VoxelMap> BaseLocalMaps::local_maps(std::size_t k) {
  std::pair<slam::VoxelMap, slam::VoxelMap> maps{slam::VoxelMap(config_.map_voxel_m, config_.map_points_per_voxel),
                                                 slam::VoxelMap(config_.map_voxel_m, config_.map_points_per_voxel)};
  const std::size_t w = static_cast<std::size_t>(std::max(config_.window, 0));
  const std::size_t first = k >= w ? k - w : 0;
  const std::size_t last = std::min(k + w, trajectory_.stamps.size() - 1);
  for (std::size_t j = first; j <= last; ++j) {
    if (trajectory_.lost[j]) continue;
    const slam::LidarFeatures& features = world_features(j);
    maps.first.add(features.edges);
    maps.second.add(features.planes);
  }
  return maps;
}

RefineResult refine_against_base(BaseLocalMaps& base, const LidarFrames& target, const SE3& T_base_target_start,
                                 const RefineConfig& config) {
  const BaseTrajectory& trajectory = base.trajectory();
  const std::size_t frames = trajectory.stamps.size();
  if (target.clouds.size() < frames)
    throw InputError(target.folder.string(), "scans", "has " + std::to_string(target.clouds.size()) + " clouds for " +
                                               std::to_string(frames) + " stamps");
  RefineResult result;
  result.start = T_base_target_start;
  result.T_base_target = T_base_target_start;
  // Step 1, eq 3.13-3.14 in the base frame at each candidate frame.
  const auto step = static_cast<std::size_t>(std::max(config.frame_step, 1));
  for (std::size_t k = 0; k < frames; k += step) {
    if (trajectory.lost[k]) continue;
    const Scan scan = load_dataset_scan(target.clouds[k], trajectory.stamps[k]);
    result.frames_tried.push_back(k);
    result.overlaps.push_back(calib::overlap_factor(base.overlap_points(k),
                                                    subsampled(scan, T_base_target_start, config.overlap_voxel_m),
                                                    config.overlap_radius_m));
  }
  const double best_overlap = result.overlaps.empty() ? 0.0 : *std::max_element(result.overlaps.begin(), result.overlaps.end());
  const double threshold = std::max(config.min_overlap, config.relative_overlap * best_overlap);
  for (std::size_t i = 0; i < result.frames_tried.size(); ++i) {
    const std::size_t k = result.frames_tried[i];
    if (!(result.overlaps[i] > threshold) || result.overlaps[i] <= 0.0) {
      ++result.frames_low_overlap;
      continue;
    }
    const Scan scan = load_dataset_scan(target.clouds[k], trajectory.stamps[k]);
    const slam::LidarFeatures features = target_features(base, target, scan, k, T_base_target_start, config);
    const auto candidate =
        register_frame(features, trajectory.T_world_base[k], T_base_target_start, k, base.local_maps(k), config);
    if (candidate) result.candidates.push_back(*candidate);
    else ++result.registrations_failed;
  }
  if (result.frames_low_overlap == result.frames_tried.size()) {
    result.verdict = RefineVerdict::no_overlap;
    result.message = "no frame's overlap factor exceeds " + std::to_string(config.min_overlap) +
                     " (eq 3.14); the LiDARs may not share a view";
    return result;
  }
  if (result.candidates.size() < config.min_candidates) {
    result.verdict = RefineVerdict::too_few_candidates;
    result.message = std::to_string(result.candidates.size()) + " registrations succeeded, " +
                     std::to_string(config.min_candidates) + " needed (more frames or a smaller frame_step help)";
    return result;
  }
  result.average = calib::average_best_candidates(result.candidates, config.selection);  // step 4
  result.T_base_target = result.average.T_base_target;
  result.verdict = RefineVerdict::ok;
  return result;
}

}  // namespace mlidar::pipelines
