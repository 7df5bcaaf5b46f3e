#include "mlidar/sim/corner_dataset.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/sim/acquisition.hpp"

namespace mlidar::sim {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kSide = 10.0;

SE3 zyx(double yaw, double pitch, double roll, const Vec3& t) { return SE3(quat_from_rpy(Vec3(roll, pitch, yaw)), t); }

SE3 configuration(int which, std::mt19937_64& rng) {
  if (which == 1) return zyx(2.7337, -0.3946, -0.1809, Vec3(0.8766, 0.4672, 1.0474));
  if (which == 2) return zyx(-0.5174, 0.1277, 0.1222, Vec3(1.3785, -1.3929, 1.3020));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Draws in statements of their own, last argument first (scene_layout.hpp: uniform).
  const double z = 3 * u(rng) - 1.5, y = 3 * u(rng) - 1.5, x = 3 * u(rng) - 1.5;
  const double roll = 20.0 * kDeg * u(rng), pitch = 20.0 * kDeg * u(rng), yaw = 360.0 * kDeg * u(rng);
  return zyx(yaw, pitch, roll, Vec3(x, y, z));
}

/// Points of the three planes and the outliers, world frame (corner at origin).
std::vector<Vec3> corner_points(const CornerSpec& spec, double alpha, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, spec.noise);
  std::normal_distribution<double> spread(0.0, 5.0);
  const Vec3 wall1(1.0, 0.0, 0.0);
  const Vec3 wall2(std::cos(alpha), std::sin(alpha), 0.0);
  const int planar = spec.points - spec.outliers;
  std::vector<Vec3> points;
  points.reserve(static_cast<std::size_t>(spec.points));
  for (int i = 0; i < planar; ++i) {
    // Draws in statements of their own, last argument first (scene_layout.hpp: uniform).
    Vec3 p;
    switch (i % 3) {
      case 0: {
        const double height = kSide * u(rng);
        p = kSide * u(rng) * wall1 + Vec3(0, 0, height);
        break;
      }
      case 1: {
        const double height = kSide * u(rng);
        p = kSide * u(rng) * wall2 + Vec3(0, 0, height);
        break;
      }
      default: {  // floor sector between the walls, uniform in area
        const double r = kSide * std::sqrt(u(rng));
        const double theta = alpha * u(rng);
        p = Vec3(r * std::cos(theta), r * std::sin(theta), 0.0);
      }
    }
    const double nz = noise(rng), ny = noise(rng), nx = noise(rng);
    points.push_back(p + Vec3(nx, ny, nz));
  }
  const Vec3 middle(0.5 * kSide * std::cos(alpha / 2), 0.5 * kSide * std::sin(alpha / 2), 0.5 * kSide);
  while (static_cast<int>(points.size()) < spec.points) {
    const double oz = spread(rng), oy = spread(rng), ox = spread(rng);
    const Vec3 offset(ox, oy, oz);
    if ((offset.array().abs() <= 0.5 * kSide).all()) points.push_back(middle + offset);
  }
  return points;
}

void write_cloud(const fs::path& file, const std::vector<Vec3>& world, const SE3& T_world_lidar) {
  const SE3 T_lidar_world = T_world_lidar.inverse();
  Scan scan;
  for (const auto& p : world) scan.points.push_back((T_lidar_world * p).cast<float>());
  io::PcdCloud cloud;
  cloud.table = io::from_scan(scan);
  io::write_pcd(file, cloud);
}

std::vector<double> angles_of(const CornerSpec& spec) {
  if (!(spec.angle_min > 0.0 && spec.angle_max < 180.0 && spec.angle_min <= spec.angle_max && spec.angle_step > 0.0))
    throw UsageError("--angles A:B[:STEP] needs 0 < A <= B < 180 and STEP > 0 (degrees)");
  std::vector<double> angles;
  for (double a = spec.angle_min; a <= spec.angle_max + 1e-9 && angles.size() < 1000; a += spec.angle_step) angles.push_back(a);
  return angles;
}

}  // namespace

void write_corner_dataset(const CornerSpec& spec, const fs::path& out) {
  if (spec.points < 3 || spec.outliers < 0 || spec.outliers > spec.points - 3)
    throw UsageError("--points must be at least 3 and exceed --outliers by 3 or more");
  if (!(spec.noise >= 0.0 && std::isfinite(spec.noise))) throw UsageError("--noise must be a non-negative number of metres");
  if (spec.configuration < 0 || spec.configuration > 2) throw UsageError("--configuration must be 1, 2 or 0 (random)");
  const std::vector<double> angles = angles_of(spec);
  std::mt19937_64 rng(spec.seed);
  const SE3 T_l1_l2 = configuration(spec.configuration, rng);

  const fs::path& dir = out;
  for (const char* name : {"l1", "l2"}) fs::create_directories(dir / "scans" / name);
  fs::create_directories(dir / "groundtruth");
  std::vector<double> stamps;
  std::string angle_lines;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    const double alpha = angles[k] * kDeg;
    const double facing = alpha / 2 + std::numbers::pi;
    const SE3 T_world_l1 = zyx(facing, 0.0, 0.0, Vec3(4.0 * std::cos(alpha / 2), 4.0 * std::sin(alpha / 2), 1.5));
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.pcd", k);
    std::mt19937_64 frame_rng(sweep_seed(spec.seed, k, 0));
    write_cloud(dir / "scans" / "l1" / name, corner_points(spec, alpha, frame_rng), T_world_l1);
    write_cloud(dir / "scans" / "l2" / name, corner_points(spec, alpha, frame_rng), T_world_l1 * T_l1_l2);
    stamps.push_back(static_cast<double>(k));
    angle_lines += std::to_string(angles[k]) + "\n";
  }
  io::Dataset dataset;
  dataset.name = "corner";
  dataset.frame_period = 1.0;
  dataset.base = "l1";
  for (const char* name : {"l1", "l2"}) {
    io::DatasetLidar lidar;
    lidar.name = name;
    lidar.model.name = "synthetic";
    lidar.scans = fs::path("scans") / name;
    dataset.lidars.push_back(lidar);
  }
  dataset.groundtruth.extrinsics = "groundtruth/extrinsics.yaml";
  io::Extrinsics truth;
  truth.base = "l1";
  truth.lidars = {{"l1", SE3(), std::nullopt}, {"l2", T_l1_l2, std::nullopt}};
  io::write_extrinsics(dir / "groundtruth" / "extrinsics.yaml", truth);
  io::write_atomically(dir / "groundtruth" / "corner_angles.txt", [&](std::ostream& s) { s << angle_lines; });
  io::write_times(dir / "times.txt", stamps);
  io::write_dataset_yaml(dir / "dataset.yaml", dataset);
}

}  // namespace mlidar::sim
