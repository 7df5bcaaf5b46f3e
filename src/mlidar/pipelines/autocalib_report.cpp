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
  nlohmann::json j = {{"verdict", calib::to_string(h.verdict)}, {"message", h.message},
                      {"estimate", pose_json(h.T_a_b)}, {"pairs_used", h.pairs_used},
                      {"pairs_rejected", h.pairs_rejected}, {"singular_values", h.singular_values},
                      {"t_z_observable", h.t_z_observable},
                      {"planar_axis", {h.planar_axis_a.x(), h.planar_axis_a.y(), h.planar_axis_a.z()}},
                      {"rotation_rms_rad", h.rotation_rms_rad}, {"translation_rms_m", h.translation_rms_m},
                      {"screw_residuals_angle_pitch_inlier", screw},
                      {"T_base_lidar", pose_json(c.T_base_lidar_handeye)},
                      {"covariance", matrix_json(c.covariance_handeye)}};
  if (c.ground) {
    j["ground"] = {{"frames_used", c.ground->frames_used}, {"shift_m", c.ground->shift_m},
                   {"spread_m", c.ground->spread_m}};
  }
  return j;
}

nlohmann::json refine_json(const LidarCalibration& c) {
  const RefineResult& r = *c.refine;
  nlohmann::json candidates = nlohmann::json::array();
  for (const auto& candidate : r.candidates)
    candidates.push_back({{"frame", candidate.frame}, {"error_m", candidate.error_m},
                          {"estimate", pose_json(candidate.T_base_target)}});
  std::vector<std::size_t> kept_frames;
  for (const std::size_t i : r.average.kept) kept_frames.push_back(r.candidates[i].frame);
  nlohmann::json j = {{"verdict", to_string(r.verdict)}, {"message", r.message}, {"start", c.refine_start},
                      {"start_estimate", pose_json(r.start)}, {"frames_tried", r.frames_tried},
                      {"overlap_ratios", r.overlaps}, {"frames_low_overlap", r.frames_low_overlap},
                      {"registrations_failed", r.registrations_failed}, {"candidates_tried", r.candidates.size()},
                      {"candidates_kept", kept_frames.size()}, {"kept_frames", kept_frames},
                      {"candidates", candidates}, {"estimate", pose_json(r.T_base_target)}};
  if (r.verdict == RefineVerdict::ok) {
    j["covariance"] = matrix_json(r.average.covariance);
    j["covariance_spread"] = matrix_json(r.average.covariance_spread);
    j["covariance_icp"] = matrix_json(r.average.covariance_icp);
    j["covariance_bias"] = matrix_json(r.average.covariance_bias);
  }
  return j;
}

nlohmann::json lidar_json(const LidarCalibration& c, bool is_base) {
  nlohmann::json j = {{"name", c.name}, {"usable", c.usable}, {"T_base_lidar", pose_json(c.T_base_lidar)},
                      {"covariance", matrix_json(c.covariance)}, {"odometry_lost_frames", c.odometry_lost_frames}};
  if (is_base) return j;
  if (c.handeye_ran) j["handeye"] = handeye_json(c);
  if (c.refine) j["refine"] = refine_json(c);
  return j;
}

}  // namespace

void write_autocalib_outputs(const AutoCalibJob& job, const AutoCalibSummary& summary) {
  std::filesystem::create_directories(job.out);
  io::Extrinsics extrinsics;
  extrinsics.base = summary.base;
  nlohmann::json lidars = nlohmann::json::array();
  for (const LidarCalibration& c : summary.lidars) {
    extrinsics.lidars.push_back({c.name, c.T_base_lidar, c.covariance});
    lidars.push_back(lidar_json(c, c.name == summary.base));
  }
  io::write_extrinsics(job.out / "extrinsics.yaml", extrinsics);
  const nlohmann::json report = {{"stage", job.stage},
                                 {"init", job.init.string()},
                                 {"base", summary.base},
                                 {"pair_stride", job.pair_stride},
                                 {"all_usable", summary.all_usable()},
                                 {"seconds", summary.seconds},
                                 {"lidars", lidars}};
  const std::string text = report.dump(2);
  io::write_atomically(job.out / "calibration.json", [&](std::ostream& out) { out << text << '\n'; });
}

}  // namespace mlidar::pipelines
