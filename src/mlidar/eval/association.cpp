#include "mlidar/eval/association.hpp"

#include <algorithm>
#include <cmath>

#include "mlidar/core/error.hpp"

namespace mlidar::eval {
namespace {

std::string pose_field(std::size_t index) { return "pose " + std::to_string(index); }

/// Index in `stamps` (sorted) nearest to `t`.
std::size_t nearest_index(const std::vector<double>& stamps, double t) {
  const auto it = std::lower_bound(stamps.begin(), stamps.end(), t);
  if (it == stamps.begin()) return 0;
  if (it == stamps.end()) return stamps.size() - 1;
  const auto after = static_cast<std::size_t>(it - stamps.begin());
  return (*it - t) < (t - *(it - 1)) ? after : after - 1;
}

std::vector<double> stamps_of(const Trajectory& trajectory) {
  std::vector<double> stamps(trajectory.size());
  for (std::size_t i = 0; i < trajectory.size(); ++i) stamps[i] = trajectory.poses[i].stamp;
  return stamps;
}

}  // namespace

void validate_trajectory(const Trajectory& trajectory, const std::string& source) {
  if (trajectory.size() < 2)
    throw InputError(source, "poses", "has " + std::to_string(trajectory.size()) + " pose(s); at least 2 are needed to evaluate");
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const StampedPose& pose = trajectory.poses[i];
    if (!std::isfinite(pose.stamp)) throw InputError(source, pose_field(i), "timestamp is not finite");
    if (!pose.T_world_base.translation().allFinite()) throw InputError(source, pose_field(i), "translation is not finite (NaN or inf)");
    const double norm = pose.T_world_base.rotation().coeffs().norm();
    if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3)
      throw InputError(source, pose_field(i), "rotation is not a unit quaternion (NaN or not normalised)");
    if (i > 0 && !(pose.stamp > trajectory.poses[i - 1].stamp))
      throw InputError(source, pose_field(i),
                       "timestamp " + std::to_string(pose.stamp) + " does not increase (previous " +
                           std::to_string(trajectory.poses[i - 1].stamp) + "); sort the file by time");
  }
}

Association associate_by_time(const Trajectory& gt, const Trajectory& est, double max_dt, const std::string& est_source) {
  const bool gt_is_shorter = gt.size() <= est.size();
  const Trajectory& shorter = gt_is_shorter ? gt : est;
  const std::vector<double> longer_stamps = stamps_of(gt_is_shorter ? est : gt);
  std::vector<std::size_t> from_shorter;
  std::vector<std::size_t> from_longer;
  std::vector<double> gaps;
  for (std::size_t i = 0; i < shorter.size(); ++i) {
    const double t = shorter.poses[i].stamp;
    const std::size_t j = nearest_index(longer_stamps, t);
    const double gap = std::abs(longer_stamps[j] - t);
    if (!(gap <= max_dt)) continue;
    if (!from_longer.empty() && from_longer.back() == j) {  // one-to-one: keep the closer pair
      if (gap < gaps.back()) {
        from_shorter.back() = i;
        gaps.back() = gap;
      }
      continue;
    }
    from_shorter.push_back(i);
    from_longer.push_back(j);
    gaps.push_back(gap);
  }
  if (from_shorter.size() < 2)
    throw InputError(est_source, "timestamp",
                     "only " + std::to_string(from_shorter.size()) + " pose(s) lie within max_dt = " + std::to_string(max_dt) +
                         " s of a ground-truth pose; check that both files use the same "
                         "clock or raise --max-dt");
  Association association;
  association.gt = gt_is_shorter ? std::move(from_shorter) : std::move(from_longer);
  association.est = gt_is_shorter ? std::move(from_longer) : std::move(from_shorter);
  return association;
}

Association associate_by_index(const Trajectory& gt, const Trajectory& est, const std::string& est_source) {
  if (gt.size() != est.size())
    throw InputError(est_source, "poses",
                     "has " + std::to_string(est.size()) + " poses but the ground truth has " + std::to_string(gt.size()) +
                         "; KITTI files are paired line by line");
  Association association;
  association.gt.resize(gt.size());
  association.est.resize(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) association.gt[i] = association.est[i] = i;
  return association;
}

}  // namespace mlidar::eval
