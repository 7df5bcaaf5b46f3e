// Scene-to-scene agreement of `calibrate refine` on real/opencalib_3lidar
// (issue 8; no answer key, the rig did not change between the three scenes).
// For left and right: every scene refined from initial_extrinsic.txt (its
// answer, reported 1-sigma and that of the ICP alone), each scene's rotation
// away from scene 0002 as a base-frame rotation vector, the max pairwise
// difference, and the same for the left-right relative pose.
// Usage: pair_refine_scenes [key=value ...]
//   ICP overrides: min_range ref_voxel k planarity kernel last_voxel last_corr
//   perturbed=1      also refine from perturbed_init/ and print the change
//   restarts=N       restart the last two ICP levels N times from the answer
//                    moved by 0.5 deg / 5 cm (seeded): how sharp the minimum is
//   reverse=1        also register the reference to the target from the answer
//                    (roles swapped, no search), print how far it lands and
//                    the spread of the reverse answers and of the midpoints
//   yaw_rate_0001=W  deskew scene 0001's top scan by a yaw rate W deg/s about
//                    its middle (a what-if for ego-motion; none is measured)
#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "mlidar/calib/pair_refine.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/opencalib.hpp"

namespace {

namespace fs = std::filesystem;
using mlidar::SE3;
using mlidar::Vec3;

struct Options {
  mlidar::calib::PairRefineConfig config;
  bool perturbed = false;
  bool reverse = false;
  int restarts = 0;
  double yaw_rate_0001_deg = 0.0;
};

fs::path data_dir() { return fs::path(MLIDAR_SHARED_DATA) / "real" / "opencalib_3lidar"; }

std::map<int, fs::path> device_clouds(const std::string& scene) {
  return mlidar::io::read_opencalib_cloud_paths(data_dir() / scene / "lidar_cloud_path.txt");
}

mlidar::Scan scan_of(const fs::path& file) { return mlidar::io::to_scan(mlidar::io::read_cloud(file).table, file.string()); }

bool apply(Options& options, const std::string& key, double value) {
  mlidar::calib::PairRefineConfig& config = options.config;
  mlidar::calib::IcpLevel& last = config.icp.levels.back();
  if (key == "min_range")
    config.min_range = value;
  else if (key == "ref_voxel")
    config.ref_voxel_size = value;
  else if (key == "k")
    config.surface.normal_neighbours = static_cast<std::size_t>(value);
  else if (key == "planarity")
    config.surface.max_planarity = value;
  else if (key == "kernel")
    last.kernel_scale = value;
  else if (key == "last_voxel")
    last.voxel_size = value;
  else if (key == "last_corr")
    last.max_correspondence = value;
  else if (key == "perturbed")
    options.perturbed = value != 0.0;
  else if (key == "reverse")
    options.reverse = value != 0.0;
  else if (key == "restarts")
    options.restarts = static_cast<int>(value);
  else if (key == "yaw_rate_0001")
    options.yaw_rate_0001_deg = value;
  else
    return false;
  return true;
}

double rotation_deg(const SE3& a, const SE3& b) {
  return mlidar::rad_to_deg(mlidar::so3_log(a.rotation().inverse() * b.rotation()).norm());
}

/// Rotates every point by -yaw_rate * (time - 0.05 s) about z: the top scan as seen at mid-sweep under a constant yaw rate.
void deskew_yaw(mlidar::Scan& scan, double yaw_rate_deg) {
  for (std::size_t k = 0; k < scan.points.size() && k < scan.time.size(); ++k) {
    const double angle = mlidar::deg_to_rad(yaw_rate_deg) * (static_cast<double>(scan.time[k]) - 0.05);
    scan.points[k] = Eigen::AngleAxisf(static_cast<float>(angle), Eigen::Vector3f::UnitZ()) * scan.points[k];
  }
}

/// Largest rotation between the answer and the ends of `count` seeded restarts of the last two ICP levels.
double restart_spread_deg(const std::vector<Eigen::Vector3f>& ref, const std::vector<Eigen::Vector3f>& target, const SE3& answer,
                          const mlidar::calib::PairRefineConfig& config, int count) {
  const auto beyond = [&](const std::vector<Eigen::Vector3f>& points) {
    std::vector<Eigen::Vector3f> kept;
    for (const Eigen::Vector3f& p : points)
      if (p.norm() >= config.min_range) kept.push_back(p);
    return mlidar::calib::voxel_downsample(kept, config.ref_voxel_size);
  };
  mlidar::calib::RefSurface surface(beyond(ref), config.surface);
  const std::vector<Eigen::Vector3f> source = beyond(target);
  mlidar::calib::IcpConfig icp = config.icp;
  icp.levels.erase(icp.levels.begin());
  std::mt19937_64 rng(1);
  std::normal_distribution<double> gauss(0.0, 1.0);
  double worst = 0.0;
  for (int k = 0; k < count; ++k) {
    const Vec3 axis(gauss(rng), gauss(rng), gauss(rng)), shift(gauss(rng), gauss(rng), gauss(rng));
    const SE3 start = SE3(mlidar::so3_exp(mlidar::deg_to_rad(0.5) * axis), 0.05 * shift) * answer;
    worst = std::max(worst, rotation_deg(answer, mlidar::calib::point_to_plane_icp(surface, source, start, icp).T_ref_source));
  }
  return worst;
}

void print_spread(const char* label, const std::vector<SE3>& poses) {
  double max_deg = 0.0, max_m = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i)
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      max_deg = std::max(max_deg, rotation_deg(poses[i], poses[j]));
      max_m = std::max(max_m, (poses[i].translation() - poses[j].translation()).norm());
    }
  std::printf("%-11s max pairwise %.3f deg %.4f m; base-frame rotation from scene 0002 [deg]:", label, max_deg, max_m);
  for (const SE3& T : poses) {
    const Vec3 d = mlidar::so3_log(T.rotation() * poses[1].rotation().inverse()) * (180.0 / 3.141592653589793);
    std::printf(" (%.3f %.3f %.3f)", d.x(), d.y(), d.z());
  }
  std::printf("\n");
}

SE3 guess(const fs::path& file, int device) {
  const mlidar::io::Extrinsics initial = mlidar::io::read_opencalib_initial_extrinsics(file);
  const auto* lidar = initial.find("device_" + std::to_string(device));
  if (lidar == nullptr) throw std::runtime_error(file.string() + ": no device_" + std::to_string(device));
  return lidar->T_base_lidar;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto eq = arg.find('=');
    if (eq == std::string::npos || !apply(options, arg.substr(0, eq), std::stod(arg.substr(eq + 1)))) {
      std::fprintf(stderr, "unknown argument %s (see the header of bench/pair_refine_scenes.cpp)\n", argv[i]);
      return 2;
    }
  }
  const std::array<std::string, 3> scenes{"0001", "0002", "0003"};
  std::map<std::string, std::vector<SE3>> answers, reversed, midpoints;
  for (const std::string& scene : scenes) {
    const auto devices = device_clouds(scene);
    mlidar::Scan top = scan_of(devices.at(0));
    if (scene == "0001" && options.yaw_rate_0001_deg != 0.0) deskew_yaw(top, options.yaw_rate_0001_deg);
    for (const auto& [id, file] : devices) {
      if (id == 0) continue;
      const std::string side = file.filename().string().rfind("left", 0) == 0 ? "left" : "right";
      const mlidar::Scan target = scan_of(file);
      const auto r =
          mlidar::calib::refine_pair(top.points, target.points, guess(data_dir() / scene / "initial_extrinsic.txt", id), options.config);
      const Vec3 rpy = mlidar::rpy_deg_from_quat(r.T_ref_target.rotation());
      const Vec3& t = r.T_ref_target.translation();
      const double icp_sd_deg = mlidar::rad_to_deg(std::sqrt(r.covariance_icp.bottomRightCorner<3, 3>().diagonal().maxCoeff()));
      std::printf("%s %-5s %-22s rpy %8.3f %7.3f %8.3f t %7.4f %7.4f %7.4f rmse %.3f overlap %.2f sd %.3f deg %.4f m (ICP alone %.3f deg)",
                  scene.c_str(), side.c_str(), std::string(to_string(r.verdict)).c_str(), rpy.x(), rpy.y(), rpy.z(), t.x(), t.y(), t.z(),
                  r.rmse, r.overlap.fraction_b, r.rotation_sd_deg, r.translation_sd_m, icp_sd_deg);
      if (options.restarts > 0)
        std::printf(" restarts within %.3f deg",
                    restart_spread_deg(top.points, target.points, r.T_ref_target, options.config, options.restarts));
      if (options.reverse) {
        mlidar::calib::PairRefineConfig reverse = options.config;
        reverse.search_mode = mlidar::calib::PairSearchMode::kNever;
        const auto b = mlidar::calib::refine_pair(target.points, top.points, r.T_ref_target.inverse(), reverse);
        const SE3 T = b.T_ref_target.inverse();
        const Vec3 d = mlidar::so3_log(T.rotation() * r.T_ref_target.rotation().inverse()) * (180.0 / 3.141592653589793);
        std::printf(" | reverse: %s, base-frame rotation (%.3f %.3f %.3f) deg, %.4f m from it", std::string(to_string(b.verdict)).c_str(),
                    d.x(), d.y(), d.z(), (T.translation() - t).norm());
        reversed[side].push_back(T);
        const Vec3 half = 0.5 * mlidar::so3_log(T.rotation() * r.T_ref_target.rotation().inverse());
        midpoints[side].push_back(SE3(mlidar::so3_exp(half) * r.T_ref_target.rotation(), 0.5 * (T.translation() + t)));
      }
      if (options.perturbed) {
        const auto p = mlidar::calib::refine_pair(top.points, target.points, guess(data_dir() / "perturbed_init" / (scene + ".txt"), id),
                                                  options.config);
        std::printf(" | perturbed: %s, %.3f deg %.4f m from it", std::string(to_string(p.verdict)).c_str(),
                    rotation_deg(p.T_ref_target, r.T_ref_target), (p.T_ref_target.translation() - t).norm());
      }
      std::printf("\n");
      answers[side].push_back(r.T_ref_target);
    }
  }
  print_spread("left", answers["left"]);
  print_spread("right", answers["right"]);
  std::vector<SE3> relative;
  for (std::size_t s = 0; s < scenes.size(); ++s) relative.push_back(answers["left"][s].inverse() * answers["right"][s]);
  print_spread("left<-right", relative);
  if (options.reverse) {
    print_spread("left rev", reversed["left"]);
    print_spread("right rev", reversed["right"]);
    print_spread("left mid", midpoints["left"]);
    print_spread("right mid", midpoints["right"]);
  }
  return 0;
}
