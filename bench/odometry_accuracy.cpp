// Long simulated odometry runs (issue 7's accuracy protocol; not a ctest, minutes long):
//   odometry_accuracy RIG SCENE TRAJECTORY FRAMES SEED [LIDARS]
// simulates each frame in memory (sim::simulate_sweep, seeded), runs
// slam::Odometry with the true extrinsics on the first LIDARS LiDARs of the rig
// and prints one markdown row: ATE (SE(3)-aligned, m), KITTI drift (devkit
// segments of 100..800 m; "-" for a path < 100 m), ms per frame (odometry only,
// simulation excluded), degenerate and lost frames.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "mlidar/eval/trajectory_metrics.hpp"
#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/rig.hpp"
#include "mlidar/sim/scenes.hpp"
#include "mlidar/sim/trajectory.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar {
namespace {

struct RunSpec {
  std::string rig, scene, trajectory;
  int frames = 300;
  std::uint64_t seed = 1;
  std::size_t lidars = 0;  ///< 0: all
};

void run(const RunSpec& spec) {
  sim::SimRig rig = sim::named_rig(spec.rig);
  if (spec.lidars > 0 && spec.lidars < rig.lidars.size()) rig.lidars.resize(spec.lidars);
  const sim::SimTrajectory trajectory = sim::SimTrajectory::named(spec.trajectory, rig.base_height);
  const double period = rig.frame_period();
  std::vector<Vec3> path;
  for (int k = 0; k <= spec.frames; ++k) path.push_back(trajectory.T_world_base(trajectory.start_time() + k * period).translation());
  const sim::Scene scene = sim::make_scene(spec.scene, spec.seed, path);
  std::vector<slam::LidarSetup> setups;
  for (const auto& lidar : rig.lidars) setups.push_back({lidar.name, lidar.model, lidar.T_base_lidar});
  slam::Odometry odometry({}, setups);
  std::vector<SE3> gt, est;
  double seconds = 0.0;
  int degenerate = 0, lost = 0;
  for (int k = 0; k < spec.frames; ++k) {
    Frame frame;
    frame.stamp = trajectory.start_time() + k * period;
    for (std::size_t i = 0; i < rig.lidars.size(); ++i)
      frame.scans.push_back(
          sim::simulate_sweep(scene, rig.lidars[i], trajectory, frame.stamp, sim::sweep_seed(spec.seed, static_cast<std::uint64_t>(k), i))
              .scan);
    const auto start = std::chrono::steady_clock::now();
    const slam::FrameResult result = odometry.process(frame);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    degenerate += result.registration.degenerate ? 1 : 0;
    lost += result.lost() ? 1 : 0;
    // The world frame is the base at the first stamp: express the truth the same way.
    gt.push_back(trajectory.T_world_base(trajectory.start_time()).inverse() * trajectory.T_world_base(frame.stamp));
    est.push_back(result.T_world_base);
  }
  const auto alignment = eval::compute_alignment(eval::AlignMode::kSe3, gt, est, "odometry");
  std::vector<SE3> aligned;
  for (const SE3& T : est) aligned.push_back(alignment.apply(T));
  const auto ate = eval::compute_ate(gt, aligned);
  const auto kitti = eval::compute_kitti_odometry(gt, est);
  double length = 0.0;
  for (std::size_t k = 1; k < gt.size(); ++k) length += (gt[k].translation() - gt[k - 1].translation()).norm();
  std::printf("| %s/%s/%s | %zu | %d | %.1f | %.4f | %s | %s | %.1f | %d | %d |\n", spec.rig.c_str(), spec.scene.c_str(),
              spec.trajectory.c_str(), rig.lidars.size(), spec.frames, length, ate.translation_m.rmse,
              kitti ? std::to_string(kitti->translation_percent).c_str() : "-",
              kitti ? std::to_string(kitti->rotation_deg_per_100m).c_str() : "-", 1e3 * seconds / spec.frames, degenerate, lost);
}

}  // namespace
}  // namespace mlidar

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: %s RIG SCENE TRAJECTORY FRAMES SEED [LIDARS]\n", argv[0]);
    return 2;
  }
  try {
    mlidar::RunSpec spec{argv[1],
                         argv[2],
                         argv[3],
                         std::atoi(argv[4]),
                         std::strtoull(argv[5], nullptr, 10),
                         argc > 6 ? static_cast<std::size_t>(std::atoi(argv[6])) : 0};
    std::printf("| run | LiDARs | frames | path m | ATE m | KITTI t %% | KITTI deg/100m | ms/frame | degenerate | lost |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
    mlidar::run(spec);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 1;
  }
  return 0;
}
