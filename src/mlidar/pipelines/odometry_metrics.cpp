#include "mlidar/pipelines/odometry_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/covariance.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/slam/pose_covariance.hpp"

namespace mlidar::pipelines {
nlohmann::json timing_summary(std::vector<double> values) {
  if (values.empty()) return {{"mean", 0.0}, {"p50", 0.0}, {"p95", 0.0}, {"max", 0.0}};
  std::sort(values.begin(), values.end());
  double sum = 0.0;
  for (const double v : values) sum += v;
  const auto at = [&](double q) { return values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5)]; };
  return {{"mean", sum / static_cast<double>(values.size())}, {"p50", at(0.5)}, {"p95", at(0.95)}, {"max", values.back()}};
}

nlohmann::json mapping_json(const std::vector<std::size_t>& lidar_uncertain, const std::optional<slam::MappingReport>& mapping,
                            const std::vector<std::string>& lidar_names) {
  if (lidar_uncertain.empty()) return nullptr;
  nlohmann::json uncertain = nlohmann::json::object();
  for (std::size_t i = 0; i < lidar_names.size() && i < lidar_uncertain.size(); ++i) uncertain[lidar_names[i]] = lidar_uncertain[i];
  nlohmann::json json{{"uncertain_features", uncertain}};
  if (mapping)
    json["map"] = {{"offered", mapping->features},
                   {"dropped_uncertain", mapping->dropped_uncertain},
                   {"added", mapping->points_added},
                   {"median_trace_m2", mapping->median_trace_m2}};
  else
    json["map"] = nullptr;  // not mapped (flagged), or the first frames (mapped again at frame 1)
  return json;
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

/// Per LiDAR: in how many frames its rows came from each source, and the rows recovered from the scans.
nlohmann::json front_end_summary(const std::vector<std::string>& names, const std::vector<slam::FrameResult>& frames) {
  nlohmann::json summary = nlohmann::json::object();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const FrontEndTally tally = front_end_tally(frames, i);
    nlohmann::json by_source = nlohmann::json::object();
    for (std::size_t source = 0; source < tally.frames.size(); ++source)
      by_source[slam::row_source_name(static_cast<slam::RowSource>(source))] = tally.frames[source];
    const std::vector<int>& rows = tally.recovered_rows;
    nlohmann::json recovered_rows = nullptr;
    if (!rows.empty()) recovered_rows = {{"min", rows.front()}, {"median", rows[rows.size() / 2]}, {"max", rows.back()}};
    summary[names[i]] = {{"frames_by_source", by_source}, {"recovered_rows", recovered_rows}};
  }
  return summary;
}

}  // namespace

std::vector<io::StampedCovariance> pose_covariances(const std::vector<slam::FrameResult>& frames) {
  slam::PoseCovarianceChain chain;
  std::vector<io::StampedCovariance> out;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    out.push_back({frames[k].stamp, covariance_in_local_tangent(frames[k].T_world_base, chain.add(frames[k], k == 0))});
  }
  return out;
}

std::string pose_sigma_words(const Mat6& covariance) {
  const Vec6 sigma = axis_sigmas(covariance);
  char text[160];
  std::snprintf(text, sizeof text, "x %.3g m, y %.3g m, z %.3g m, rotation %.2g deg", sigma(0), sigma(1), sigma(2),
                rad_to_deg(sigma.tail<3>().maxCoeff()));
  return text;
}

std::string last_pose_note(const Mat6& covariance, std::size_t lost_at_end) {
  const std::string sigma = "last pose 1-sigma " + pose_sigma_words(covariance);
  if (lost_at_end == 0) return sigma + " (grown from 0 at the first frame; every frame's in pose_covariance.txt)";
  return sigma + ": a prediction, not an estimate (the last " + std::to_string(lost_at_end) +
         " frame(s) were lost and each adds the prediction's doubt; every frame's in pose_covariance.txt)";
}

std::string map_restart_warning(const std::vector<std::size_t>& frames, const slam::OdometryConfig& config) {
  if (frames.empty()) return {};
  std::string text = "warning: the local map was started again at frame";
  text += frames.size() == 1 ? " " : "s ";
  for (std::size_t i = 0; i < frames.size(); ++i) text += (i > 0 ? ", " : "") + std::to_string(frames[i]);
  return text + ", after " + std::to_string(config.restart_after_lost) +
         " failed registrations in a row (odometry.restart_after_lost) or " + std::to_string(config.restart_after_suspect) +
         " frames in a row not trusted (odometry.restart_after_suspect): the trajectory after each restart is "
         "measured again, but joins the one before through the motion prediction alone, so the offset there is unknown "
         "(metrics.json map_restarts)\n";
}

void add_pose_covariance_traces(nlohmann::json& metrics, const std::vector<io::StampedCovariance>& covariances) {
  nlohmann::json& per_frame = metrics["per_frame"];
  for (std::size_t k = 0; k < covariances.size() && k < per_frame.size(); ++k)
    per_frame[k]["pose_covariance_trace"] = covariances[k].covariance.trace();
}

FrontEndTally front_end_tally(const std::vector<slam::FrameResult>& frames, std::size_t lidar) {
  FrontEndTally tally;
  for (const slam::FrameResult& f : frames) {
    if (lidar >= f.lidar_row_source.size()) continue;
    const slam::RowSource source = f.lidar_row_source[lidar];
    ++tally.frames[static_cast<std::size_t>(source)];
    if (source == slam::RowSource::kRecovered) tally.recovered_rows.push_back(f.lidar_rows[lidar]);
    if (source == slam::RowSource::kRingChannel) tally.ring_channel_rows.push_back(f.lidar_rows[lidar]);
  }
  std::sort(tally.recovered_rows.begin(), tally.recovered_rows.end());
  std::sort(tally.ring_channel_rows.begin(), tally.ring_channel_rows.end());
  return tally;
}

std::vector<std::pair<std::string, std::size_t>> degenerate_direction_counts(const std::vector<slam::FrameResult>& frames) {
  std::vector<std::pair<std::string, std::size_t>> counts;
  for (const slam::FrameResult& f : frames) {
    if (!f.registration.degenerate) continue;
    const std::string words = base_axis_words(weak_translation_base(f));
    const auto entry = std::find_if(counts.begin(), counts.end(), [&words](const auto& e) { return e.first == words; });
    if (entry == counts.end())
      counts.emplace_back(words, 1);
    else
      ++entry->second;
  }
  std::stable_sort(counts.begin(), counts.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  return counts;
}

std::string base_axis_words(const Vec3& direction_base) {
  Eigen::Index axis = 0;
  direction_base.cwiseAbs().maxCoeff(&axis);
  static constexpr const char* kWords[] = {"x (forward-backward)", "y (left-right)", "z (up-down)"};
  return kWords[axis];
}

Vec3 weak_translation_base(const slam::FrameResult& frame) {
  const slam::RegistrationResult& r = frame.registration;
  if (!r.degenerate) return Vec3::Zero();
  return r.T_world_base.rotation().conjugate() * r.weak_translation;
}

nlohmann::json odometry_metrics_json(const std::vector<slam::FrameResult>& frames, const std::vector<slam::LidarSetup>& lidars) {
  nlohmann::json json;
  json["frames"] = frames.size();
  std::vector<std::string> names;
  for (const auto& lidar : lidars) names.push_back(lidar.name);
  json["lidars"] = names;
  std::vector<double> total, points_in, features_out;
  std::size_t degenerate = 0, retried = 0, lost = 0, suspect = 0;
  std::vector<std::size_t> map_restarts;  // frames that started a new local map
  for (std::size_t s = 0; s < slam::kStageCount; ++s) {
    std::vector<double> stage;
    for (const auto& f : frames) stage.push_back(f.seconds[s]);
    json["stages"][slam::stage_name(static_cast<slam::Stage>(s))] = timing_summary(stage);
  }
  nlohmann::json per_frame = nlohmann::json::array();
  for (const auto& f : frames) {
    nlohmann::json weak = nullptr, weak_words = nullptr;
    if (f.registration.degenerate) {
      const Vec3 direction = weak_translation_base(f);
      weak = {direction.x(), direction.y(), direction.z()};
      weak_words = base_axis_words(direction);
    }
    nlohmann::json front_end;
    for (std::size_t i = 0; i < names.size() && i < f.lidar_rows.size(); ++i)
      front_end[names[i]] = {{"rows", f.lidar_rows[i]}, {"source", slam::row_source_name(f.lidar_row_source[i])}};
    double sum = 0.0;
    for (const double v : f.seconds) sum += v;
    total.push_back(sum);
    points_in.push_back(static_cast<double>(f.points_in));
    features_out.push_back(static_cast<double>(f.edge_features + f.plane_features));
    degenerate += f.registration.degenerate ? 1 : 0;
    retried += f.retried ? 1 : 0;
    lost += f.lost() ? 1 : 0;
    if (f.map_restarted) map_restarts.push_back(per_frame.size());
    suspect += f.suspect() ? 1 : 0;
    const auto& r = f.registration;
    per_frame.push_back({{"stamp", f.stamp},
                         {"eigenvalues", std::vector<double>(r.eigenvalues.data(), r.eigenvalues.data() + 6)},
                         {"translation_observability", r.translation_observability},
                         {"degenerate", r.degenerate},
                         {"weak_translation_base", weak},
                         {"weak_direction", weak_words},
                         {"lost", f.lost()},
                         {"map_restarted", f.map_restarted},
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
                         {"selection", selection_json(f.selection_summary(), names)},
                         {"uncertainty", mapping_json(f.lidar_uncertain, f.mapping, names)}});
  }
  json["total_seconds"] = timing_summary(total);
  json["points_in"] = timing_summary(points_in);
  json["features_out"] = timing_summary(features_out);
  json["degenerate_frames"] = degenerate;
  nlohmann::json degenerate_directions = nlohmann::json::object();
  for (const auto& [words, count] : degenerate_direction_counts(frames)) degenerate_directions[words] = count;
  json["degenerate_directions"] = degenerate_directions;
  json["retried_frames"] = retried;
  json["lost_frames"] = lost;
  json["map_restarts"] = map_restarts;
  json["suspect_frames"] = suspect;
  json["front_end"] = front_end_summary(names, frames);
  json["per_frame"] = std::move(per_frame);
  return json;
}

MapCloud map_cloud(const slam::Odometry& odometry) {
  MapCloud map{odometry.plane_map().points(), std::nullopt, odometry.plane_map().sources(), {}};
  const auto edges = odometry.edge_map().points();
  map.points.insert(map.points.end(), edges.begin(), edges.end());
  const auto edge_sources = odometry.edge_map().sources();
  map.lidars.insert(map.lidars.end(), edge_sources.begin(), edge_sources.end());
  for (const slam::LidarSetup& lidar : odometry.lidars()) map.lidar_names.push_back(lidar.name);
  if (odometry.config().uncertainty.enabled) {
    map.covariances.emplace();
    for (const slam::VoxelMap* part : {&odometry.plane_map(), &odometry.edge_map()})
      for (const slam::PointCovariance& c : part->covariances()) map.covariances->push_back(c.upper);
  }
  return map;
}

void write_map_ply(const std::filesystem::path& path, const slam::Odometry& odometry) { write_map_ply(path, map_cloud(odometry)); }

void write_map_ply(const std::filesystem::path& path, const MapCloud& map) {
  Scan scan;
  scan.points = map.points;
  io::CloudFile cloud;
  cloud.format = io::CloudFormat::kPly;
  cloud.table = io::from_scan(scan);
  if (map.covariances) io::add_point_covariances(cloud.table, *map.covariances);
  if (map.lidars.size() == map.points.size() && !map.lidar_names.empty()) {
    io::FieldColumn& column = cloud.table.add_field("lidar", io::ScalarType::kU8);
    if (!map.lidars.empty()) std::memcpy(column.data.data(), map.lidars.data(), map.lidars.size());
  }
  io::write_cloud(path, cloud);
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
