#include "mlidar/pipelines/odometry_metrics.hpp"

#include <algorithm>
#include <cmath>

#include "mlidar/io/cloud_file.hpp"

namespace mlidar::pipelines {
nlohmann::json timing_summary(std::vector<double> values) {
  if (values.empty()) return {{"mean", 0.0}, {"p50", 0.0}, {"p95", 0.0}, {"max", 0.0}};
  std::sort(values.begin(), values.end());
  double sum = 0.0;
  for (const double v : values) sum += v;
  const auto at = [&](double q) { return values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5)]; };
  return {{"mean", sum / static_cast<double>(values.size())}, {"p50", at(0.5)}, {"p95", at(0.95)}, {"max", values.back()}};
}

nlohmann::json selection_json(const std::optional<slam::SelectionSummary>& summary, const std::vector<std::string>& lidar_names) {
  if (!summary) return nullptr;
  const slam::SelectionReport& s = summary->report;
  nlohmann::json per_lidar;
  std::size_t features = 0, selected = 0;
  for (std::size_t i = 0; i < lidar_names.size() && i < summary->lidar_selected.size(); ++i) {
    per_lidar[lidar_names[i]] = {{"features", summary->lidar_features[i]}, {"selected", summary->lidar_selected[i]}};
    features += summary->lidar_features[i];
    selected += summary->lidar_selected[i];
  }
  const auto& degeneracy = summary->full_set_degeneracy;
  return {{"method", slam::selection_method_name(s.method)},
          {"features", features},
          {"searched", s.screened},
          {"matched", s.screened_matches},
          {"budget", s.budget},
          {"selected", selected},
          {"log_det_full", degeneracy ? nlohmann::json(degeneracy->log_det) : nlohmann::json()},
          {"translation_observability_full", degeneracy ? nlohmann::json(degeneracy->translation_observability) : nlohmann::json()},
          {"log_det_selected", s.log_det_selected},
          {"degenerate_scene", summary->degenerate_scene},
          {"stopped_by_time", s.stopped_by_time},
          {"seconds", s.seconds},
          {"held_out", s.held_out},
          {"held_out_matches", s.held_out_matches},
          {"held_out_mean_residual_m", s.held_out_mean_residual_m},
          {"fell_back", s.fell_back},
          {"per_lidar", per_lidar}};
}

namespace {

/// Per LiDAR: in how many frames its rows came from the model, were recovered (and how many), or the voxel fallback ran.
nlohmann::json front_end_summary(const std::vector<std::string>& names, std::size_t frames,
                                 const std::vector<std::vector<int>>& recovered_rows, const std::vector<std::size_t>& fallback_frames) {
  nlohmann::json summary = nlohmann::json::object();
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::vector<int> rows = recovered_rows[i];
    std::sort(rows.begin(), rows.end());
    nlohmann::json recovered = {{"frames", rows.size()}};
    if (!rows.empty()) recovered.update({{"rows_min", rows.front()}, {"rows_median", rows[rows.size() / 2]}, {"rows_max", rows.back()}});
    summary[names[i]] = {{"model_frames", frames - rows.size() - fallback_frames[i]},
                         {"recovered", recovered},
                         {"voxel_fallback_frames", fallback_frames[i]}};
  }
  return summary;
}

}  // namespace

nlohmann::json odometry_metrics_json(const std::vector<slam::FrameResult>& frames, const std::vector<slam::LidarSetup>& lidars) {
  nlohmann::json json;
  json["frames"] = frames.size();
  std::vector<std::string> names;
  for (const auto& lidar : lidars) names.push_back(lidar.name);
  json["lidars"] = names;
  std::vector<double> total, points_in, features_out;
  std::size_t degenerate = 0, retried = 0, lost = 0, suspect = 0;
  for (std::size_t s = 0; s < slam::kStageCount; ++s) {
    std::vector<double> stage;
    for (const auto& f : frames) stage.push_back(f.seconds[s]);
    json["stages"][slam::stage_name(static_cast<slam::Stage>(s))] = timing_summary(stage);
  }
  nlohmann::json per_frame = nlohmann::json::array();
  std::vector<std::vector<int>> recovered_rows(names.size());
  std::vector<std::size_t> fallback_frames(names.size(), 0);
  for (const auto& f : frames) {
    nlohmann::json front_end;
    for (std::size_t i = 0; i < names.size() && i < f.lidar_rows.size(); ++i) {
      front_end[names[i]] = {{"rows", f.lidar_rows[i]}, {"source", slam::row_source_name(f.lidar_row_source[i])}};
      if (f.lidar_row_source[i] == slam::RowSource::kRecovered) recovered_rows[i].push_back(f.lidar_rows[i]);
      fallback_frames[i] += f.lidar_row_source[i] == slam::RowSource::kVoxelFallback ? 1 : 0;
    }
    double sum = 0.0;
    for (const double v : f.seconds) sum += v;
    total.push_back(sum);
    points_in.push_back(static_cast<double>(f.points_in));
    features_out.push_back(static_cast<double>(f.edge_features + f.plane_features));
    degenerate += f.registration.degenerate ? 1 : 0;
    retried += f.retried ? 1 : 0;
    lost += f.lost() ? 1 : 0;
    suspect += f.suspect() ? 1 : 0;
    const auto& r = f.registration;
    per_frame.push_back({{"stamp", f.stamp},
                         {"eigenvalues", std::vector<double>(r.eigenvalues.data(), r.eigenvalues.data() + 6)},
                         {"translation_observability", r.translation_observability},
                         {"degenerate", r.degenerate},
                         {"lost", f.lost()},
                         {"suspect", f.suspect()},
                         {"trust", slam::trust_name(f.trust)},
                         {"recent_residual_m", std::isfinite(f.recent_residual_m) ? nlohmann::json(f.recent_residual_m) : nlohmann::json()},
                         {"retried", f.retried},
                         {"iterations", r.iterations},
                         {"converged", r.converged},
                         {"match_ratio", r.match_ratio()},
                         {"mean_residual_m", r.mean_residual_m},
                         {"threshold_m", f.threshold_m},
                         {"edges", f.edge_features},
                         {"planes", f.plane_features},
                         {"front_end", front_end},
                         {"selection", selection_json(f.selection_summary(), names)}});
  }
  json["total_seconds"] = timing_summary(total);
  json["points_in"] = timing_summary(points_in);
  json["features_out"] = timing_summary(features_out);
  json["degenerate_frames"] = degenerate;
  json["retried_frames"] = retried;
  json["lost_frames"] = lost;
  json["suspect_frames"] = suspect;
  json["front_end"] = front_end_summary(names, frames.size(), recovered_rows, fallback_frames);
  json["per_frame"] = std::move(per_frame);
  return json;
}

void write_map_ply(const std::filesystem::path& path, const slam::Odometry& odometry) {
  std::vector<Eigen::Vector3f> points = odometry.plane_map().points();
  const auto edges = odometry.edge_map().points();
  points.insert(points.end(), edges.begin(), edges.end());
  write_map_ply(path, std::move(points));
}

void write_map_ply(const std::filesystem::path& path, std::vector<Eigen::Vector3f> points) {
  Scan map;
  map.points = std::move(points);
  io::CloudFile cloud;
  cloud.format = io::CloudFormat::kPly;
  cloud.table = io::from_scan(map);
  io::write_cloud(path, cloud);
}

}  // namespace mlidar::pipelines
