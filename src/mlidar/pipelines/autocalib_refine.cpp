#include "mlidar/pipelines/autocalib_refine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/slam/deskew.hpp"
#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::pipelines {
namespace {

/// Sigma of a zero-mean Gaussian from its mean absolute value: E|r| = sigma sqrt(2 / pi).
double residual_variance(double mean_abs_residual) {
  const double sigma = mean_abs_residual * std::sqrt(std::numbers::pi / 2.0);
  return sigma * sigma;
}

std::vector<Eigen::Vector3f> moved(const std::vector<Eigen::Vector3f>& points, const SE3& T) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(T * p);
  return out;
}

void move_all(std::vector<Eigen::Vector3f>& points, const SE3& T) {
  for (auto& p : points) p = T * p;
}

/// The target's features at frame k in its own frame at the stamp, deskewed with
/// the base velocity carried to the target by X0 (T_rel_target = X0^-1 T_rel_base X0).
slam::LidarFeatures target_features(const BaseLocalMaps& base, const TargetFrames& target, const Scan& scan, std::size_t k, const SE3& X0,
                                    const RefineConfig& config) {
  const slam::BodyVelocity v_base = base.velocity(k);
  constexpr double kDt = 0.1;  // any positive interval: the velocity is what is carried
  const SE3 T_rel_target = X0.inverse() * v_base.pose_at(kDt) * X0;
  const slam::LidarSetup setup{target.name, target.model, SE3::identity()};
  slam::FrontEndWorkspace workspace;
  slam::LidarFeatures features;
  slam::StageSeconds seconds{};
  slam::run_front_end(scan, base.trajectory().stamps[k], setup, slam::BodyVelocity::from_relative_pose(T_rel_target, kDt), config.front_end,
                      workspace, features, seconds);
  return features;
}

/// The registration's H, without the information along the translation a degenerate registration kept at its
/// start (slam::register_scan_to_map): that component was not measured, so it must not pull a fusion.
Mat6 without_weak_translation(const slam::RegistrationResult& registration) {
  if (!registration.degenerate) return registration.hessian;
  const Vec3& weak = registration.weak_translation;
  Mat6 P = Mat6::Identity();
  P.topLeftCorner<3, 3>() -= weak * weak.transpose();
  return P.transpose() * registration.hessian * P;
}

/// Step 3: coarse then fine registration from T_world_base_k X0.
std::optional<calib::ExtrinsicCandidate> register_frame(const slam::LidarFeatures& features, const SE3& T_world_base, const SE3& X0,
                                                        std::size_t k, const std::pair<slam::VoxelMap, slam::VoxelMap>& maps,
                                                        const RefineConfig& config) {
  const auto& [edge_map, plane_map] = maps;
  const slam::RegistrationResult coarse = slam::register_scan_to_map(
      features.edges, features.planes, edge_map, plane_map, T_world_base * X0, config.coarse_correspondence_m, config.registration);
  const slam::RegistrationResult fine = slam::register_scan_to_map(features.edges, features.planes, edge_map, plane_map,
                                                                   coarse.T_world_base, config.fine_correspondence_m, config.registration);
  if (fine.match_ratio() < config.min_match_ratio) return std::nullopt;
  calib::ExtrinsicCandidate candidate;
  candidate.frame = k;
  candidate.degenerate = fine.degenerate;
  candidate.T_base_target = T_world_base.inverse() * fine.T_world_base;
  candidate.error_m = fine.mean_residual_m;
  candidate.information = calib::extrinsic_information(without_weak_translation(fine), residual_variance(fine.mean_residual_m),
                                                       T_world_base, candidate.T_base_target);
  return candidate;
}

}  // namespace

const char* to_string(RefineVerdict verdict) {
  switch (verdict) {
    case RefineVerdict::ok:
      return "ok";
    case RefineVerdict::no_overlap:
      return "no_overlap";
    case RefineVerdict::too_few_candidates:
      return "too_few_candidates";
  }
  return "unknown";
}

std::vector<Eigen::Vector3f> overlap_subsample(const Scan& scan, double voxel_m) {
  std::vector<Eigen::Vector3f> out;
  for (const std::uint32_t i : slam::voxel_subsample(scan.points, voxel_m)) out.push_back(scan.points[i]);
  return out;
}

BaseLocalMaps::BaseLocalMaps(std::string name, LidarModel model, RefineConfig config)
    : name_(std::move(name)), model_(std::move(model)), config_(std::move(config)) {}

void BaseLocalMaps::add_pose(double stamp, const SE3& T_world_base, bool lost) {
  trajectory_.stamps.push_back(stamp);
  trajectory_.T_world_base.push_back(T_world_base);
  trajectory_.lost.push_back(lost);
  world_features_.emplace_back();
  overlap_points_.emplace_back();
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

void BaseLocalMaps::add_scan(std::size_t k, const Scan& scan) {
  const auto step = static_cast<std::size_t>(std::max(config_.frame_step, 1));
  if (trajectory_.lost.at(k)) return;
  if (k % step == 0) overlap_points_[k] = overlap_subsample(scan, config_.overlap_voxel_m);
  const slam::LidarSetup setup{name_, model_, SE3::identity()};
  slam::LidarFeatures features;
  slam::StageSeconds seconds{};
  slam::run_front_end(scan, trajectory_.stamps[k], setup, velocity(k), config_.front_end, workspace_, features, seconds);
  move_all(features.edges, trajectory_.T_world_base[k]);
  move_all(features.planes, trajectory_.T_world_base[k]);
  world_features_[k] = std::move(features);
}

const std::vector<Eigen::Vector3f>& BaseLocalMaps::overlap_points(std::size_t k) const { return overlap_points_.at(k); }

std::pair<slam::VoxelMap, slam::VoxelMap> BaseLocalMaps::local_maps(std::size_t k) const {
  std::pair<slam::VoxelMap, slam::VoxelMap> maps{slam::VoxelMap(config_.map_voxel_m, config_.map_points_per_voxel),
                                                 slam::VoxelMap(config_.map_voxel_m, config_.map_points_per_voxel)};
  const std::size_t w = static_cast<std::size_t>(std::max(config_.window, 0));
  const std::size_t first = k >= w ? k - w : 0;
  const std::size_t last = std::min(k + w, trajectory_.stamps.size() - 1);
  for (std::size_t j = first; j <= last; ++j) {
    if (trajectory_.lost[j] || !world_features_[j]) continue;
    maps.first.add(world_features_[j]->edges);
    maps.second.add(world_features_[j]->planes);
  }
  return maps;
}

std::vector<Eigen::Vector3f> BaseLocalMaps::local_points(std::size_t k, std::size_t window) const {
  std::vector<Eigen::Vector3f> points;
  const std::size_t first = k >= window ? k - window : 0;
  const std::size_t last = std::min(k + window, trajectory_.stamps.size() - 1);
  const SE3 T_base_world = trajectory_.T_world_base.at(k).inverse();
  for (std::size_t j = first; j <= last; ++j) {
    if (trajectory_.lost[j] || !world_features_[j]) continue;
    for (const auto* features : {&world_features_[j]->edges, &world_features_[j]->planes})
      for (const auto& p : *features) points.push_back(T_base_world * p);
  }
  return points;
}

namespace {

/// Steps 1-3 from `start`: the overlap of every candidate frame, then a registration of those that pass.
void register_frames(const BaseLocalMaps& base, const TargetFrames& target, const SE3& start, const RefineConfig& config,
                     RefineResult& result) {
  const BaseTrajectory& trajectory = base.trajectory();
  result.frames_tried.clear();
  result.overlaps.clear();
  result.candidates.clear();
  result.frames_low_overlap = 0;
  result.registrations_failed = 0;
  const auto step = static_cast<std::size_t>(std::max(config.frame_step, 1));
  for (std::size_t k = 0; k < trajectory.stamps.size(); k += step) {  // eq 3.13-3.14 in the base frame
    if (trajectory.lost[k] || !target.overlap_points.at(k) || base.overlap_points(k).empty()) continue;
    result.frames_tried.push_back(k);
    result.overlaps.push_back(
        calib::overlap_factor(base.overlap_points(k), moved(*target.overlap_points[k], start), config.overlap_radius_m));
  }
  const double best_overlap = result.overlaps.empty() ? 0.0 : *std::max_element(result.overlaps.begin(), result.overlaps.end());
  const double threshold = std::max(config.min_overlap, config.relative_overlap * best_overlap);
  for (std::size_t i = 0; i < result.frames_tried.size(); ++i) {
    const std::size_t k = result.frames_tried[i];
    if (!(result.overlaps[i] > threshold) || result.overlaps[i] <= 0.0) {
      ++result.frames_low_overlap;
      continue;
    }
    const std::optional<Scan> scan = target.read_scan(k);
    if (!scan) {  // it was usable in stage 1: the file changed since
      ++result.registrations_failed;
      continue;
    }
    const slam::LidarFeatures features = target_features(base, target, *scan, k, start, config);
    const auto candidate = register_frame(features, trajectory.T_world_base[k], start, k, base.local_maps(k), config);
    if (candidate)
      result.candidates.push_back(*candidate);
    else
      ++result.registrations_failed;
  }
}

/// Step 4 over the registrations that fixed the whole extrinsic; `kept` indexes result.candidates. False: too few.
bool average_full(const RefineConfig& config, RefineResult& result) {
  std::vector<calib::ExtrinsicCandidate> full;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < result.candidates.size(); ++i)
    if (!result.candidates[i].degenerate) {
      full.push_back(result.candidates[i]);
      index.push_back(i);
    }
  if (full.size() < config.min_candidates) return false;
  result.average = calib::average_best_candidates(full, config.selection);
  for (std::size_t& kept : result.average.kept) kept = index[kept];
  return true;
}

/// Step 4 when too few registrations fix the whole extrinsic but the degenerate ones, fused by their information,
/// observe every direction: fused, registered again from the fused estimate and fused once more.
bool fuse_degenerate(const BaseLocalMaps& base, const TargetFrames& target, const RefineConfig& config, RefineResult& result) {
  if (result.candidates.size() < config.min_candidates) return false;
  calib::InformationFusion fusion = calib::fuse_by_information(result.candidates, result.start, config.selection);
  for (int pass = 0; pass < config.fusion_passes; ++pass) {
    register_frames(base, target, fusion.T_base_target, config, result);
    if (result.candidates.size() < config.min_candidates) return false;
    fusion = calib::fuse_by_information(result.candidates, fusion.T_base_target, config.selection);
  }
  result.fusion = fusion;
  return fusion.translation_sd_m <= config.max_fused_translation_sd_m && fusion.rotation_sd_deg <= config.max_fused_rotation_sd_deg;
}

}  // namespace

RefineResult refine_against_base(const BaseLocalMaps& base, const TargetFrames& target, const SE3& T_base_target_start,
                                 const RefineConfig& config) {
  RefineResult result;
  result.start = T_base_target_start;
  result.T_base_target = T_base_target_start;
  register_frames(base, target, T_base_target_start, config, result);
  if (result.frames_low_overlap == result.frames_tried.size()) {
    result.verdict = RefineVerdict::no_overlap;
    result.message =
        "no frame's overlap factor exceeds " + std::to_string(config.min_overlap) + " (eq 3.14); the LiDARs may not share a view";
    return result;
  }
  if (average_full(config, result)) {  // step 4
    result.T_base_target = result.average.T_base_target;
    result.verdict = RefineVerdict::ok;
    return result;
  }
  const auto degenerate = static_cast<std::size_t>(
      std::count_if(result.candidates.begin(), result.candidates.end(), [](const auto& c) { return c.degenerate; }));
  const std::size_t full = result.candidates.size() - degenerate;
  if (fuse_degenerate(base, target, config, result)) {
    result.T_base_target = result.fusion->T_base_target;
    result.verdict = RefineVerdict::ok;
    return result;
  }
  result.verdict = RefineVerdict::too_few_candidates;
  result.message = std::to_string(full) + " registrations fixed the whole extrinsic, " + std::to_string(config.min_candidates) +
                   " needed; the " + std::to_string(degenerate) + " degenerate ones";
  if (result.fusion) {
    const calib::InformationFusion& fusion = *result.fusion;
    const Vec3& w = fusion.weak_direction;
    char text[200];
    std::snprintf(text, sizeof text,
                  " fused leave %.1f cm / %.2f deg (1 sigma) along the weakest direction (%.2f, %.2f, %.2f) of the base frame",
                  100.0 * fusion.translation_sd_m, fusion.rotation_sd_deg, w.x(), w.y(), w.z());
    result.message += text;
    result.fusion.reset();
  } else {
    result.message += " are too few";
  }
  result.message += " (more frames at turns or near surfaces facing along the drive, a smaller frame_step or a better --init help)";
  return result;
}

}  // namespace mlidar::pipelines
