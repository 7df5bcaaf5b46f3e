#include "mlidar/pipelines/slam_appearance_start.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

namespace mlidar::pipelines {

RefineConfig appearance_refine_config() {
  RefineConfig config;
  config.max_fused_translation_sd_m = 0.1;
  config.max_fused_rotation_sd_deg = 1.0;
  return config;
}

AppearanceHistory::AppearanceHistory(std::size_t capacity, std::size_t frame_step)
    : capacity_(capacity), frame_step_(std::max<std::size_t>(frame_step, 1)) {}

void AppearanceHistory::add(std::size_t index, double stamp, const SE3& T_world_base, bool flagged,
                            const std::vector<std::optional<Scan>>& scans, const std::vector<bool>& keep) {
  if (capacity_ <= 1) return;  // appearance_after_frames 0: never used
  KeptFrame frame{index, stamp, T_world_base, flagged, std::vector<std::optional<Scan>>(scans.size())};
  frame.scans[0] = scans[0];
  if (index % frame_step_ == 0)
    for (std::size_t j = 1; j < scans.size(); ++j)
      if (keep[j]) frame.scans[j] = scans[j];
  frames_.push_back(std::move(frame));
  if (frames_.size() > capacity_) frames_.pop_front();
}

std::optional<AppearanceHistory::Inputs> AppearanceHistory::inputs(std::size_t first, const slam::LidarSetup& base,
                                                                  const slam::LidarSetup& lidar, std::size_t j,
                                                                  const RefineConfig& refine) const {
  // Local frame 0 is a candidate frame, so that the refinement's k % frame_step == 0 are the frames kept with j's scans.
  auto from = std::find_if(frames_.begin(), frames_.end(),
                           [&](const KeptFrame& f) { return f.index >= first && f.index % frame_step_ == 0; });
  if (std::distance(from, frames_.end()) < 2) return std::nullopt;
  const auto offset = static_cast<std::size_t>(std::distance(frames_.begin(), from));
  const std::size_t n = frames_.size() - offset;
  Inputs out{BaseLocalMaps(base.name, base.model, refine),
             TargetFrames{lidar.name, lidar.model, std::vector<std::optional<std::vector<Eigen::Vector3f>>>(n),
                          [this, offset, j](std::size_t k) { return frames_.at(offset + k).scans.at(j); }},
             from->index};
  const std::optional<Scan>* previous = nullptr;
  for (std::size_t k = 0; k < n; ++k) {
    const KeptFrame& f = frames_[offset + k];
    out.base.add_pose(f.stamp, f.T_world_base, f.flagged || !f.scans[0]);
    if (previous != nullptr && *previous) out.base.add_scan(k - 1, **previous);  // its deskew velocity needed pose k
    previous = &f.scans[0];
    if (f.scans[j]) out.target.overlap_points[k] = overlap_subsample(*f.scans[j], refine.overlap_voxel_m);
  }
  if (*previous) out.base.add_scan(n - 1, **previous);
  return out;
}

AppearanceAttempt appearance_start(const AppearanceHistory& history, std::size_t first, const slam::LidarSetup& base,
                                   const slam::LidarSetup& lidar, std::size_t j, const SE3& guess, const AppearanceStartConfig& config) {
  const auto started = std::chrono::steady_clock::now();
  AppearanceAttempt attempt;
  RefineConfig refine = config.refine;
  refine.frame_step = static_cast<int>(history.frame_step());
  const std::optional<AppearanceHistory::Inputs> inputs = history.inputs(first, base, lidar, j, refine);
  if (!inputs) {
    attempt.verdict = "no_frames";
    attempt.message = "fewer than two frames kept since it began initializing";
    return attempt;
  }
  attempt.frames_used = inputs->base.trajectory().stamps.size();
  const AppearanceCalibration calibration =
      calibrate_by_appearance(inputs->base, inputs->target, guess, refine, config.search ? &config.start_search : nullptr);
  attempt.searched = calibration.search.has_value();
  if (calibration.search && calibration.search->T_base_target) attempt.search_label = calibration.search->label;
  const RefineResult* result = calibration.result();
  attempt.ok = calibration.ok();
  attempt.verdict = result != nullptr ? to_string(result->verdict) : "no_start";
  attempt.message = result != nullptr ? result->message : "no refinement ran";
  if (attempt.ok) attempt.T_base_lidar = result->T_base_target;
  attempt.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return attempt;
}

}  // namespace mlidar::pipelines
