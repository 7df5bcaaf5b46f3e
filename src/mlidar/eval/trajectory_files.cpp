#include "mlidar/eval/trajectory_files.hpp"

#include <vector>

#include "mlidar/core/error.hpp"
#include "mlidar/eval/report.hpp"
#include "mlidar/io/pose_covariance_io.hpp"
#include "mlidar/io/trajectory_io.hpp"

namespace mlidar::eval {
namespace {

bool is_kitti(const TrajectoryFiles& files) {
  if (!files.format.empty()) return files.format == "kitti";
  return files.gt.extension() == ".kitti";
}

}  // namespace

AlignMode parse_align_mode(const std::string& name) {
  if (name == "none") return AlignMode::kNone;
  if (name == "origin") return AlignMode::kOrigin;
  if (name == "se3") return AlignMode::kSe3;
  if (name == "sim3") return AlignMode::kSim3;
  throw UsageError("--align is '" + name + "': use none, origin, se3 or sim3");
}

TrajectoryFileEvaluation evaluate_trajectory_files(const TrajectoryFiles& files, TrajectoryEvalOptions options) {
  if (!files.format.empty() && files.format != "tum" && files.format != "kitti")
    throw UsageError("--format is '" + files.format + "': use tum or kitti");
  const bool kitti = is_kitti(files);
  options.associate_by_index = kitti;
  const Trajectory gt = kitti ? io::read_kitti_poses(files.gt) : io::read_tum(files.gt);
  const Trajectory est = kitti ? io::read_kitti_poses(files.est) : io::read_tum(files.est);
  TrajectoryFileEvaluation out;
  out.report = evaluate_trajectory(gt, est, options, files.gt.string(), files.est.string());
  out.json = to_json(out.report);
  if (!files.covariance.empty()) {
    const std::vector<io::StampedCovariance> covariances = io::read_pose_covariances(files.covariance);
    std::vector<double> est_stamps;
    for (const StampedPose& pose : est.poses) est_stamps.push_back(pose.stamp);
    out.nees = evaluate_pose_nees(out.report, covariances, files.covariance.string(), est_stamps);
    out.json["pose_nees"] = to_json(*out.nees);
  }
  return out;
}

}  // namespace mlidar::eval
