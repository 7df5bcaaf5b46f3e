#pragma once
// Consistency of a run's pose covariances (RUN/pose_covariance.txt) against a
// ground-truth trajectory: the normalized estimation error squared per frame,
// NEES = e^T C^-1 e, with e = [t_gt - t_est, Log(R_est^T R_gt)] in the file's
// tangent ([t additive, r local]), after aligning the estimate to the truth at
// its first pose (the covariance is zero there and grows from it). A
// consistent covariance puts 95 % of the frames inside the two-sided chi^2
// 95 % band (6 dof: [1.237, 14.449]; the translation block alone, 3 dof:
// [0.216, 9.348]); below the band it is too large, above too small.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mlidar/eval/trajectory_metrics.hpp"
#include "mlidar/io/pose_covariance_io.hpp"

namespace mlidar::eval {

struct NeesBand {
  std::size_t frames = 0;  ///< frames with an invertible covariance
  double median = 0.0;
  double inside = 0.0;  ///< shares of the frames, in [0, 1]
  double below = 0.0;
  double above = 0.0;
  double low = 0.0;  ///< the band
  double high = 0.0;
};

struct PoseNees {
  NeesBand pose;               ///< 6 dof
  NeesBand translation;        ///< 3 dof, the translation block
  std::size_t skipped = 0;     ///< associated poses without a covariance (none within max_dt) or a singular one (the first)
  std::vector<double> stamps;  ///< of the frames in `pose`
  std::vector<double> values;  ///< their 6-dof NEES
};

/// `report`: the trajectory evaluation (its associated poses before alignment); `est_stamps`: the estimated
/// trajectory's stamps (by index). Estimated pose k takes the file's line k when their stamps agree within
/// report.options.max_dt (always, when the report associated by index), else the line nearest in stamp within
/// it; none: skipped. Throws InputError (source,
/// "stamps") when no pose has a positive-definite covariance.
PoseNees evaluate_pose_nees(const TrajectoryReport& report, std::span<const io::StampedCovariance> covariances, const std::string& source,
                            std::span<const double> est_stamps);

}  // namespace mlidar::eval
