#include "mlidar/eval/report.hpp"

#include <cmath>
#include <cstdio>

#include "mlidar/core/fixed_decimals.hpp"

namespace mlidar::eval {
namespace {

nlohmann::json number_or_null(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

std::string stats_row(const char* label, const ErrorStats& stats) {
  char buffer[200];
  std::snprintf(buffer, sizeof(buffer), "%-26s %10s %10s %10s %10s\n", label, fixed(stats.rmse, 4).c_str(), fixed(stats.mean, 4).c_str(),
                fixed(stats.median, 4).c_str(), fixed(stats.max, 4).c_str());
  return buffer;
}

}  // namespace

nlohmann::json to_json(const ErrorStats& stats) {
  return {{"count", stats.count},
          {"rmse", number_or_null(stats.rmse)},
          {"mean", number_or_null(stats.mean)},
          {"median", number_or_null(stats.median)},
          {"std", number_or_null(stats.std)},
          {"min", number_or_null(stats.min)},
          {"max", number_or_null(stats.max)}};
}

nlohmann::json to_json(const TrajectoryReport& report) {
  const Alignment& alignment = report.alignment;
  const Vec3& t = alignment.T_gt_est.translation();
  const Quat& q = alignment.T_gt_est.rotation();
  nlohmann::json json = {
      {"gt_poses", report.gt_poses},
      {"est_poses", report.est_poses},
      {"matched_poses", report.gt.size()},
      {"alignment",
       {{"mode", align_mode_name(alignment.mode)},
        {"scale", alignment.scale},
        {"translation", {t.x(), t.y(), t.z()}},
        {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}}},
      {"ate", {{"translation_m", to_json(report.ate.translation_m)}, {"rotation_deg", to_json(report.ate.rotation_deg)}}},
      {"rpe",
       {{"delta", report.rpe.delta},
        {"delta_unit", delta_unit_name(report.rpe.unit)},
        {"translation_m", to_json(report.rpe.translation_m)},
        {"translation_percent", to_json(report.rpe.translation_percent)},
        {"rotation_deg", to_json(report.rpe.rotation_deg)}}},
      {"kitti", nullptr}};
  if (report.kitti.has_value()) {
    json["kitti"] = {{"segments", report.kitti->segments},
                     {"translation_percent", report.kitti->translation_percent},
                     {"rotation_deg_per_100m", report.kitti->rotation_deg_per_100m},
                     {"by_length", nlohmann::json::array()}};
    for (const KittiLengthDrift& drift : report.kitti->by_length)
      json["kitti"]["by_length"].push_back({{"length_m", drift.length_m},
                                            {"segments", drift.segments},
                                            {"translation_percent", drift.translation_percent},
                                            {"rotation_deg_per_100m", drift.rotation_deg_per_100m}});
  }
  return json;
}

nlohmann::json to_json(const std::vector<ExtrinsicError>& errors) {
  nlohmann::json lidars = nlohmann::json::array();
  for (const ExtrinsicError& error : errors) {
    lidars.push_back({{"name", error.name},
                      {"rotation_error_deg", error.rotation_error_deg},
                      {"translation_error_m", error.translation_error_m},
                      {"nees", error.nees.has_value() ? nlohmann::json(*error.nees) : nlohmann::json()},
                      {"nees_bound_95", kChiSquare6Dof95},
                      {"nees_within_95", error.nees.has_value() ? nlohmann::json(error.nees_within_95()) : nlohmann::json()}});
  }
  return {{"lidars", lidars}};
}

nlohmann::json to_json(const MapMetrics& metrics, const MapMetricsOptions& options) {
  return {{"points", metrics.points},
          {"points_used", metrics.points_used},
          {"radius_m", options.radius},
          {"min_neighbors", options.min_neighbors},
          {"mean_map_entropy", number_or_null(metrics.mean_map_entropy)},
          {"mean_plane_variance", number_or_null(metrics.mean_plane_variance)},
          {"covariance_trace", metrics.covariance_trace ? nlohmann::json{{"points", metrics.covariance_trace->count},
                                                                         {"mean_m2", number_or_null(metrics.covariance_trace->mean)},
                                                                         {"p50_m2", number_or_null(metrics.covariance_trace->p50)},
                                                                         {"p95_m2", number_or_null(metrics.covariance_trace->p95)},
                                                                         {"max_m2", number_or_null(metrics.covariance_trace->max)}}
                                                        : nlohmann::json(nullptr)}};
}

std::string format_table(const TrajectoryReport& report) {
  std::string text = "poses: " + std::to_string(report.gt.size()) + " matched (gt " + std::to_string(report.gt_poses) + ", est " +
                     std::to_string(report.est_poses) + "), alignment " + align_mode_name(report.alignment.mode) + ", scale " +
                     fixed(report.alignment.scale, 6) + "\n";
  char header[200];
  std::snprintf(header, sizeof(header), "%-26s %10s %10s %10s %10s\n", "metric", "rmse", "mean", "median", "max");
  text += header;
  text += stats_row("ATE trans (m)", report.ate.translation_m);
  text += stats_row("ATE rot (deg)", report.ate.rotation_deg);
  char delta[32];
  std::snprintf(delta, sizeof(delta), "%g", report.rpe.delta);
  const std::string rpe = std::string("RPE/") + delta + delta_unit_name(report.rpe.unit);
  text += stats_row((rpe + " trans (m)").c_str(), report.rpe.translation_m);
  text += stats_row((rpe + " trans (%)").c_str(), report.rpe.translation_percent);
  text += stats_row((rpe + " rot (deg)").c_str(), report.rpe.rotation_deg);
  if (report.kitti.has_value()) {
    text += "KITTI odometry: " + fixed(report.kitti->translation_percent, 4) + " %, " + fixed(report.kitti->rotation_deg_per_100m, 4) +
            " deg/100m over " + std::to_string(report.kitti->segments) + " segments\n";
  } else {
    text += "KITTI odometry: path shorter than 100 m, not computed\n";
  }
  return text;
}

std::string format_table(const std::vector<ExtrinsicError>& errors) {
  char line[200];
  std::snprintf(line, sizeof(line), "%-16s %12s %12s %12s\n", "lidar", "rot (deg)", "trans (m)", "NEES (<=12.59)");
  std::string text = line;
  for (const ExtrinsicError& error : errors) {
    const std::string nees = error.nees.has_value() ? fixed(*error.nees, 3) + (error.nees_within_95() ? " ok" : " OUT") : std::string("-");
    std::snprintf(line, sizeof(line), "%-16s %12s %12s %12s\n", error.name.c_str(), fixed(error.rotation_error_deg, 4).c_str(),
                  fixed(error.translation_error_m, 4).c_str(), nees.c_str());
    text += line;
  }
  return text;
}

std::string format_table(const MapMetrics& metrics, const MapMetricsOptions& options) {
  return "points: " + std::to_string(metrics.points) + " (" + std::to_string(metrics.points_used) +
         " with a full-rank neighbourhood, radius " + fixed(options.radius, 3) + " m)\n" +
         "mean map entropy:    " + fixed(metrics.mean_map_entropy, 4) + "\n" +
         "mean plane variance: " + fixed(metrics.mean_plane_variance, 8) + " m^2\n" +
         (metrics.covariance_trace
              ? "point covariance tr(Sigma): mean " + fixed(metrics.covariance_trace->mean, 6) + ", median " +
                    fixed(metrics.covariance_trace->p50, 6) + ", p95 " + fixed(metrics.covariance_trace->p95, 6) + ", max " +
                    fixed(metrics.covariance_trace->max, 6) + " m^2 over " + std::to_string(metrics.covariance_trace->count) + " points\n"
              : std::string("point covariances: none in the map\n"));
}

nlohmann::json to_json(const SurfaceError& error, const SurfaceErrorOptions& options) {
  nlohmann::json normalized = nullptr;
  if (error.normalized)
    normalized = {{"points", error.normalized->count},
                  {"mean", number_or_null(error.normalized->mean)},
                  {"variance", number_or_null(error.normalized->variance)},
                  {"inside_95", number_or_null(error.normalized->inside_95)}};
  return {{"points", error.points},
          {"matched", error.matched},
          {"max_distance_m", options.max_distance_m},
          {"distance_m", to_json(error.distance_m)},
          {"signed_mean_m", number_or_null(error.signed_mean_m)},
          {"normalized_error", normalized}};
}

std::string format_table(const SurfaceError& error, const SurfaceErrorOptions& options) {
  std::string text = "distance to the true surfaces: " + std::to_string(error.matched) + " of " + std::to_string(error.points) +
                     " points within " + fixed(options.max_distance_m, 2) + " m; |distance| mean " + fixed(error.distance_m.mean, 4) +
                     " m, rmse " + fixed(error.distance_m.rmse, 4) + " m, max " + fixed(error.distance_m.max, 4) + " m, signed mean " +
                     fixed(error.signed_mean_m, 4) + " m\n";
  if (!error.normalized) return text + "normalized error: the map has no point covariances\n";
  return text + "normalized error along the normal: variance " + fixed(error.normalized->variance, 3) +
         " (1 when the covariances are honest), mean " + fixed(error.normalized->mean, 3) + ", " +
         fixed(100 * error.normalized->inside_95, 1) + " % inside the 95 % bound over " + std::to_string(error.normalized->count) +
         " points\n";
}

namespace {

nlohmann::json band_json(const NeesBand& band) {
  return {{"frames", band.frames}, {"median", band.median}, {"inside", band.inside},
          {"below", band.below},   {"above", band.above},   {"band_95", {band.low, band.high}}};
}

std::string band_line(const char* what, const NeesBand& band) {
  return std::string(what) + ": " + fixed(100 * band.inside, 1) + " % of " + std::to_string(band.frames) +
         " frames inside the 95 % band [" + fixed(band.low, 2) + ", " + fixed(band.high, 2) + "] (" + fixed(100 * band.below, 1) +
         " % below: covariance too large; " + fixed(100 * band.above, 1) + " % above: too small), median " + fixed(band.median, 2) + "\n";
}

}  // namespace

nlohmann::json to_json(const PoseNees& nees) {
  return {{"skipped", nees.skipped},
          {"pose", band_json(nees.pose)},
          {"translation", band_json(nees.translation)},
          {"stamps", nees.stamps},
          {"values", nees.values}};
}

std::string format_table(const PoseNees& nees) {
  return band_line("pose NEES (6 dof, aligned at the first pose)", nees.pose) + band_line("translation NEES (3 dof)", nees.translation) +
         (nees.skipped > 0
              ? std::to_string(nees.skipped) + " pose(s) without a usable covariance (the first, or no stamp within --max-dt)\n"
              : std::string());
}

}  // namespace mlidar::eval
