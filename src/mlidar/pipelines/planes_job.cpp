#include "mlidar/pipelines/planes_job.hpp"

#include <chrono>
#include <vector>

#include "mlidar/calib/planes_calibrator.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/pipelines/planes_config.hpp"

namespace mlidar::pipelines {
namespace {

namespace fs = std::filesystem;

std::string lidar_name(const std::string& path, const std::string& fallback) {
  const std::string stem = fs::path(path).stem().string();
  return stem.empty() ? fallback : stem;
}

/// T_ref_target from an extrinsics file that names both LiDARs (or whose base is the reference).
SE3 read_guess(const std::string& path, const std::string& ref_name, const std::string& target_name) {
  const io::Extrinsics extrinsics = io::read_extrinsics(path);
  const io::LidarExtrinsic* target = extrinsics.find(target_name);
  if (target == nullptr) throw InputError(path, "lidars." + target_name, "missing; --init must name the target LiDAR");
  const io::LidarExtrinsic* ref = extrinsics.find(ref_name);
  if (ref == nullptr && extrinsics.base != ref_name)
    throw InputError(path, "lidars." + ref_name, "missing; --init must name the reference LiDAR or use it as base");
  return ref == nullptr ? target->T_base_lidar : ref->T_base_lidar.inverse() * target->T_base_lidar;
}

nlohmann::json pose_json(const SE3& T) {
  const Quat& q = T.rotation();
  return {{"translation", {T.translation().x(), T.translation().y(), T.translation().z()}},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

nlohmann::json cloud_json(const calib::CloudCornerReport& cloud) {
  nlohmann::json planes = nlohmann::json::array();
  const char* names[3] = {"left", "right", "bottom"};
  for (int i = 0; i < 3; ++i) {
    const auto& p = cloud.planes[i];
    planes.push_back({{"name", names[i]},
                      {"normal", {p.plane.normal.x(), p.plane.normal.y(), p.plane.normal.z()}},
                      {"offset", p.plane.offset},
                      {"inliers", p.inliers},
                      {"residual_rms_m", p.residual_rms}});
  }
  return {{"planes_found", cloud.planes_found},
          {"planes", planes},
          {"angles_deg", {cloud.angles_deg[0], cloud.angles_deg[1], cloud.angles_deg[2]}},
          {"corner", {cloud.corner.x(), cloud.corner.y(), cloud.corner.z()}}};
}

nlohmann::json report_json(const calib::PlanesResult& result, double seconds) {
  nlohmann::json warnings = nlohmann::json::array();
  for (const auto w : result.warnings) warnings.push_back(calib::warning_name(w));
  std::vector<double> covariance(result.covariance.data(), result.covariance.data() + 36);  // symmetric
  return {{"verdict", result.ok() ? "ok" : "warning"},
          {"warnings", warnings},
          {"T_ref_target", pose_json(result.T_ref_target)},
          {"T_ref_target_closed_form", pose_json(result.T_ref_target_closed_form)},
          {"covariance", covariance},
          {"residual_sigma_m", result.residual_sigma},
          {"rotation_sigma_max_deg", result.rotation_sigma_max_deg},
          {"iterations", result.iterations},
          {"converged", result.converged},
          {"seconds", seconds},
          {"ref", cloud_json(result.ref)},
          {"target", cloud_json(result.target)}};
}

}  // namespace

PlanesJobResult run_planes_job(const PlanesJob& job) {
  PlanesJobResult out;
  out.ref_name = lidar_name(job.ref.string(), "ref");
  out.target_name = lidar_name(job.target.string(), "target");
  if (out.target_name == out.ref_name) out.target_name = "target";
  calib::PlanesConfig config;
  if (!job.config.empty()) config = parse_planes_config(io::read_file_text(job.config), job.config.string());
  const calib::PlanesCalibrator calibrator(config);
  if (!job.init.empty()) out.guess = read_guess(job.init.string(), out.ref_name, out.target_name);
  out.ref = io::to_scan(io::read_cloud(job.ref).table, job.ref.string());
  out.target = io::to_scan(io::read_cloud(job.target).table, job.target.string());
  const auto start = std::chrono::steady_clock::now();
  out.result = calibrator.calibrate(out.ref.points, out.target.points, out.guess, job.ref.string(), job.target.string());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

io::Extrinsics planes_extrinsics(const PlanesJobResult& job) {
  io::Extrinsics extrinsics;
  extrinsics.base = job.ref_name;
  extrinsics.lidars = {{job.ref_name, SE3(), std::nullopt}, {job.target_name, job.result.T_ref_target, job.result.covariance}};
  return extrinsics;
}

nlohmann::json planes_report_json(const PlanesJobResult& job) { return report_json(job.result, job.seconds); }

}  // namespace mlidar::pipelines
