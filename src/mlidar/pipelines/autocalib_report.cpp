#include "mlidar/pipelines/autocalib_report.hpp"

#include <nlohmann/json.hpp>

#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"

namespace mlidar::pipelines {
namespace {

nlohmann::json pose_json(const SE3& T) {
  const Quat& q = T.rotation();
  return {{"translation", {T.translation().x(), T.translation().y(), T.translation().z()}},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

std::vector<double> matrix_json(const Mat6& m) { return {m.data(), m.data() + 36}; }  // symmetric

nlohmann::json handeye_json(const LidarCalibration& c) {
  const calib::HandEyeResult& h = c.hand_eye;
  nlohmann::json screw = nlohmann::json::array();
  for (const auto& s : h.screw) screw.push_back({s.angle_rad, s.pitch_m, s.inlier});
  nlohmann::json j = {{"verdict", calib::to_string(h.verdict)},
                      {"message", h.message},
                      {"estimate", pose_json(h.T_a_b)},
                      {"pairs_used", h.pairs_used},
                      {"pairs_rejected", h.pairs_rejected},
                      {"singular_values", h.singular_values},
                      {"t_z_observable", h.t_z_observable},
                      {"planar_axis", {h.planar_axis_a.x(), h.planar_axis_a.y(), h.planar_axis_a.z()}},
                      {"rotation_rms_rad", h.rotation_rms_rad},
                      {"translation_rms_m", h.translation_rms_m},
                      {"screw_residuals_angle_pitch_inlier", screw},
                      {"T_base_lidar", pose_json(c.T_base_lidar_handeye)},
                      {"covariance", matrix_json(c.covariance_handeye)}};
  if (c.ground) {
    j["ground"] = {{"frames_used", c.ground->frames_used}, {"shift_m", c.ground->shift_m}, {"spread_m", c.ground->spread_m}};
  }
  return j;
}

nlohmann::json refine_json(const RefineResult& r, RefineStart start) {
  nlohmann::json candidates = nlohmann::json::array();
  for (const auto& candidate : r.candidates)
    candidates.push_back({{"frame", candidate.frame},
                          {"error_m", candidate.error_m},
                          {"degenerate", candidate.degenerate},
                          {"estimate", pose_json(candidate.T_base_target)}});
  std::vector<std::size_t> kept_frames;
  for (const std::size_t i : r.average.kept) kept_frames.push_back(r.candidates[i].frame);
  nlohmann::json j = {{"verdict", to_string(r.verdict)},
                      {"message", r.message},
                      {"start", to_string(start)},
                      {"start_estimate", pose_json(r.start)},
                      {"frames_tried", r.frames_tried},
                      {"overlap_ratios", r.overlaps},
                      {"frames_low_overlap", r.frames_low_overlap},
                      {"registrations_failed", r.registrations_failed},
                      {"candidates_tried", r.candidates.size()},
                      {"candidates_kept", kept_frames.size()},
                      {"kept_frames", kept_frames},
                      {"candidates", candidates},
                      {"estimate", pose_json(r.T_base_target)}};
  if (r.verdict == RefineVerdict::ok && r.fusion) {
    j["fused_by_information"] = true;
    j["covariance"] = matrix_json(r.fusion->covariance);
    j["fusion"] = {{"chi2_per_dof", r.fusion->chi2_per_dof},
                   {"translation_observability", r.fusion->translation_observability},
                   {"translation_sd_m", r.fusion->translation_sd_m},
                   {"rotation_sd_deg", r.fusion->rotation_sd_deg},
                   {"weak_direction", {r.fusion->weak_direction.x(), r.fusion->weak_direction.y(), r.fusion->weak_direction.z()}}};
  } else if (r.verdict == RefineVerdict::ok) {
    j["fused_by_information"] = false;
    j["covariance"] = matrix_json(r.average.covariance);
    j["covariance_spread"] = matrix_json(r.average.covariance_spread);
    j["covariance_icp"] = matrix_json(r.average.covariance_icp);
    j["covariance_bias"] = matrix_json(r.average.covariance_bias);
  }
  return j;
}

nlohmann::json search_json(const StartSearchResult& s) {
  return {{"found", s.T_base_target.has_value()},
          {"estimate", s.T_base_target ? pose_json(*s.T_base_target) : nlohmann::json(nullptr)},
          {"label", s.label},
          {"score", s.score},
          {"runner_up_score", s.runner_up_score},
          {"frames", s.frames},
          {"starts_per_frame", s.starts_per_frame}};
}

/// c's result in the output frame (the base LiDAR: where it places the frame, exactly).
SE3 result_in_frame(const LidarCalibration& c, bool is_base, const BaseFrame& frame) {
  return is_base ? frame.T_base_reference : frame.extrinsic_to_base(c.T_base_lidar);
}

nlohmann::json lidar_json(const LidarCalibration& c, bool is_base, const BaseFrame& frame) {
  const nlohmann::json given = c.given ? pose_json(*c.given) : nlohmann::json(nullptr);
  nlohmann::json j = {
      {"name", c.name},
      {"usable", c.usable},
      {"verdict", c.usable ? "ok" : "not_calibrated"},
      {"reason", c.reason},
      {"advice", c.advice},
      {"T_base_lidar", c.usable ? pose_json(result_in_frame(c, is_base, frame)) : given},
      {"covariance", c.usable ? nlohmann::json(matrix_json(frame.covariance_to_base(c.covariance))) : nlohmann::json(nullptr)},
      {"odometry_lost_frames", c.odometry_lost_frames}};
  if (is_base) return j;
  if (c.handeye_ran) j["handeye"] = handeye_json(c);
  if (c.refine) j["refine"] = refine_json(*c.refine, c.refine_start);
  if (c.refine_unsearched) j["refine_unsearched"] = refine_json(*c.refine_unsearched, c.unsearched_start);
  if (c.search) j["search"] = search_json(*c.search);
  return j;
}

}  // namespace

void write_autocalib_outputs(const AutoCalibJob& job, const AutoCalibSummary& summary, const nlohmann::json& skipped_scans) {
  std::filesystem::create_directories(job.out);
  io::Extrinsics extrinsics;
  const BaseFrame& frame = summary.frame;
  extrinsics.base = frame.name;
  nlohmann::json lidars = nlohmann::json::array();
  for (const LidarCalibration& c : summary.lidars) {
    const bool is_base = c.name == summary.base;
    // Not calibrated: the input's extrinsic without a covariance, or nothing; never an unchecked guess.
    if (c.usable)
      extrinsics.lidars.push_back({c.name, result_in_frame(c, is_base, frame), frame.covariance_to_base(c.covariance)});
    else if (c.given)
      extrinsics.lidars.push_back({c.name, *c.given, std::nullopt});
    lidars.push_back(lidar_json(c, is_base, frame));
  }
  io::write_extrinsics(job.out / "extrinsics.yaml", extrinsics);
  const nlohmann::json report = {
      {"stage", to_string(job.stage)},  {"init", job.init.string()},          {"base", summary.base},       {"frame", frame.name},
      {"pair_stride", job.pair_stride}, {"all_usable", summary.all_usable()}, {"seconds", summary.seconds}, {"lidars", lidars},
      {"skipped_scans", skipped_scans}};
  const std::string text = report.dump(2);
  io::write_atomically(job.out / "calibration.json", [&](std::ostream& out) { out << text << '\n'; });
}

}  // namespace mlidar::pipelines
