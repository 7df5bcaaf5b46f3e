#include "mlidar/pipelines/slam_metrics.hpp"

#include "mlidar/core/conversions.hpp"
#include "mlidar/pipelines/odometry_metrics.hpp"

namespace mlidar::pipelines {
namespace {

nlohmann::json number_or_null(double value) { return value < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(value); }

template <typename T>
nlohmann::json optional_json(const std::optional<T>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

nlohmann::json stage_timings(const std::vector<SlamFrame>& frames, const std::vector<double>& load_seconds, nlohmann::json& total) {
  std::vector<double> odometry, initialization, calibration, shock, window, sum;
  for (const auto& f : frames) {
    odometry.push_back(f.seconds.odometry);
    initialization.push_back(f.seconds.initialization);
    calibration.push_back(f.seconds.calibration);
    shock.push_back(f.seconds.shock);
    window.push_back(f.seconds.window);
    sum.push_back(f.seconds.odometry + f.seconds.initialization + f.seconds.calibration + f.seconds.shock + f.seconds.window);
  }
  total = timing_summary(sum);
  return {{"load", timing_summary(load_seconds)},
          {"odometry", timing_summary(odometry)},
          {"initialization", timing_summary(initialization)},
          {"calibration", timing_summary(calibration)},
          {"shock", timing_summary(shock)},
          {"window", timing_summary(window)}};
}

nlohmann::json pose_json(const SE3& T) {
  const Quat q = T.rotation();
  const Vec3 t = T.translation();
  return {{"translation", {t.x(), t.y(), t.z()}}, {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

nlohmann::json lidar_frame_json(const SlamLidarFrame& l) {
  return {{"window_estimate", l.window_estimate ? pose_json(*l.window_estimate) : nlohmann::json(nullptr)},
          {"role", std::string(to_string(l.role))},
          {"scan_missing", l.scan_missing},
          {"lambda_min", number_or_null(l.lambda_min)},
          {"accepted", l.accepted},
          {"mean_residual_m", number_or_null(l.mean_residual_m)},
          {"shock", l.shock},
          {"window_information", l.window_information
                                     ? nlohmann::json(std::vector<double>(l.window_information->data(), l.window_information->data() + 36))
                                     : nlohmann::json(nullptr)},
          {"window_residual_variance_m2", number_or_null(l.window_residual_variance_m2)},
          {"window_step_m", number_or_null(l.window_step_m)},
          {"window_step_deg", number_or_null(l.window_step_deg)},
          {"window_settled", l.window_settled},
          {"reinitialized", l.reinitialized},
          {"residual_ratio", number_or_null(l.residual_ratio)},
          {"map_ratio", number_or_null(l.map_ratio)},
          {"extrinsic_disagrees", l.extrinsic_disagrees}};
}

/// The given-extrinsic check's verdict (calib/extrinsic_check.hpp): null when it never disagreed.
nlohmann::json extrinsic_check_json(const SlamLidarReport& l) {
  if (!l.disagreement) return nullptr;
  const SE3 T_given_current = l.given_T_base_lidar.inverse() * l.T_base_lidar;
  return {{"disagreed_frame", l.disagreement->frame},
          {"residual_ratio", number_or_null(l.disagreement->residual_ratio)},
          {"map_ratio", number_or_null(l.disagreement->map_ratio)},
          {"frames_lost", l.disagreement->frames_lost},
          {"recalibrated", l.disagreement->recalibrated},
          {"from_first_frame", l.disagreement->from_first_frame},
          {"after_shock", l.disagreement->after_shock},
          {"given", pose_json(l.given_T_base_lidar)},
          {"current_minus_given_m", T_given_current.translation().norm()},
          {"current_minus_given_deg", rad_to_deg(Eigen::AngleAxisd(T_given_current.rotation()).angle())}};
}

nlohmann::json matrix_json_6(const Mat6& m) { return std::vector<double>(m.data(), m.data() + 36); }

/// Xi_calib's terms (calib/extrinsic_covariance.hpp), null before convergence.
nlohmann::json covariance_terms_json(const std::optional<calib::CalibrationCovariance>& parts) {
  if (!parts) return nullptr;
  return {{"autocorrelation_time", parts->autocorrelation_time},
          {"spread", matrix_json_6(parts->spread)},
          {"bias", matrix_json_6(parts->bias)},
          {"windows", matrix_json_6(parts->windows)}};
}

/// Every appearance start of a LiDAR (slam_appearance_start.hpp).
nlohmann::json appearance_json(const std::vector<AppearanceAttempt>& attempts) {
  nlohmann::json out = nlohmann::json::array();
  for (const AppearanceAttempt& a : attempts) {
    nlohmann::json estimate = nullptr;
    if (a.T_base_lidar) {
      const Quat q = a.T_base_lidar->rotation();
      const Vec3 t = a.T_base_lidar->translation();
      estimate = {{"translation", {t.x(), t.y(), t.z()}}, {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
    }
    out.push_back({{"frame", a.frame},
                   {"frames_used", a.frames_used},
                   {"ok", a.ok},
                   {"verdict", a.verdict},
                   {"message", a.message},
                   {"searched", a.searched},
                   {"search_start", a.search_label.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.search_label)},
                   {"estimate", estimate},
                   {"seconds", a.seconds}});
  }
  return out;
}

nlohmann::json lidar_report_json(const SlamLidarReport& l) {
  const auto window_observed = [](const SlamLidarReport& r) { return r.converged_frame.has_value() || r.accepted > 0; };
  const auto& init = l.initialization;
  nlohmann::json weak = nlohmann::json::array();
  for (const auto& w : l.weak) weak.push_back({{"description", w.description}, {"eigenvalue", w.eigenvalue}});
  const Quat q = l.T_base_lidar.rotation();
  const Vec3 t = l.T_base_lidar.translation();
  nlohmann::json covariance = nullptr;
  if (l.covariance) covariance = std::vector<double>(l.covariance->data(), l.covariance->data() + 36);  // symmetric: order irrelevant
  return {{"role", std::string(to_string(l.role))},
          {"translation", {t.x(), t.y(), t.z()}},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}},
          {"covariance", covariance},
          {"covariance_terms", covariance_terms_json(l.covariance_parts)},
          {"initialization",
           {{"state", std::string(calib::to_string(init.state))},
            {"frame", optional_json(l.initialized_frame)},
            {"pairs_stored", init.pairs_stored},
            {"pairs_seen", init.pairs_seen},
            {"singular_values", init.singular_values},
            {"translation_eigenvalues", init.translation_eigenvalues},
            {"rotation_rms_rad", init.rotation_rms_rad},
            {"planar_motion", init.planar_motion},
            {"pairs_translation", init.pairs_translation},
            {"translation_std_m", number_or_null(init.translation_std_m)},
            {"planar_rotation", init.planar_rotation},
            {"translation_start",
             l.translation_start == TranslationStart::none ? nlohmann::json(nullptr) : nlohmann::json(to_string(l.translation_start))},
            {"unobservable_from_motion", l.unobservable_from_motion},
            {"axis_translation_source", l.axis_translation_source == AxisTranslationSource::none
                                            ? nlohmann::json(nullptr)
                                            : nlohmann::json(to_string(l.axis_translation_source))},
            {"observable_in_window", l.unobservable_from_motion.empty() ? nlohmann::json(nullptr) : nlohmann::json(window_observed(l))},
            {"unobservable_axis_base", {init.unobservable_axis_base.x(), init.unobservable_axis_base.y(), init.unobservable_axis_base.z()}},
            {"appearance", appearance_json(l.appearance_attempts)}}},
          {"converged_frame", optional_json(l.converged_frame)},
          {"first_converged_frame", optional_json(l.first_converged_frame)},
          {"accepted", l.accepted},
          {"outlier_windows", l.outliers},
          {"restarts", l.restarts},
          {"shock_frames", l.shock_frames},
          {"reinitialization_frames", l.reinitialization_frames},
          {"missing_frames", l.missing_frames},
          {"weak_directions", weak},
          {"extrinsic_check", extrinsic_check_json(l)}};
}

}  // namespace

nlohmann::json slam_metrics_json(const std::vector<SlamFrame>& frames, const std::vector<std::size_t>& order,
                                 const std::vector<SlamLidarReport>& lidars, const std::vector<double>& load_seconds,
                                 std::string_view calibrate) {
  nlohmann::json json;
  json["frames"] = frames.size();
  json["calibrate"] = calibrate;
  json["lidars"] = nlohmann::json::array();
  for (const auto& l : lidars) json["lidars"].push_back(l.name);
  nlohmann::json total;
  json["stages"] = stage_timings(frames, load_seconds, total);
  json["total_seconds"] = total;
  std::size_t lost = 0, suspect = 0, changes = 0, calibrating = 0;
  std::vector<std::size_t> map_restarts;  // frames that started a new local map
  nlohmann::json per_frame = nlohmann::json::array();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const SlamFrame& f = frames[i];
    lost += f.lost ? 1 : 0;
    if (f.map_restarted) map_restarts.push_back(i);
    suspect += f.suspect ? 1 : 0;
    changes += f.trusted_changed ? 1 : 0;
    calibrating += f.calibrating ? 1 : 0;
    nlohmann::json per_lidar = nlohmann::json::object();
    for (std::size_t e = 0; e < f.lidars.size(); ++e) per_lidar[lidars.at(order.at(e)).name] = lidar_frame_json(f.lidars[e]);
    per_frame.push_back({{"stamp", f.stamp},
                         {"mode", f.calibrating ? "calibration" : "odometry"},
                         {"lost", f.lost},
                         {"map_restarted", f.map_restarted},
                         {"suspect", f.suspect},
                         {"trusted_changed", f.trusted_changed},
                         {"lidars", per_lidar},
                         {"selection", selection_json(f.selection, f.selection_lidars)},
                         {"uncertainty", mapping_json(f.uncertain_features, f.mapping, f.uncertainty_lidars)},
                         {"seconds",
                          {{"load", i < load_seconds.size() ? load_seconds[i] : 0.0},
                           {"odometry", f.seconds.odometry},
                           {"initialization", f.seconds.initialization},
                           {"calibration", f.seconds.calibration},
                           {"shock", f.seconds.shock},
                           {"window", f.seconds.window}}}});
  }
  json["lost_frames"] = lost;
  json["map_restarts"] = map_restarts;
  json["suspect_frames"] = suspect;
  json["trusted_set_changes"] = changes;
  json["calibration_frames"] = calibrating;
  json["per_frame"] = std::move(per_frame);
  for (const auto& l : lidars) json["per_lidar"][l.name] = lidar_report_json(l);
  return json;
}

}  // namespace mlidar::pipelines
