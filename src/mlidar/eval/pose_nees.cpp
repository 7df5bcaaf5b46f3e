#include "mlidar/eval/pose_nees.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "mlidar/core/error.hpp"

namespace mlidar::eval {
namespace {

// Two-sided chi^2 95 % bands (2.5 % and 97.5 % quantiles).
constexpr double kChi2Low6 = 1.2373442457912035, kChi2High6 = 14.449375335447922;
constexpr double kChi2Low3 = 0.21579528262451893, kChi2High3 = 9.348403604496148;

NeesBand band_of(std::vector<double> values, double low, double high) {
  NeesBand band;
  band.low = low;
  band.high = high;
  band.frames = values.size();
  if (values.empty()) return band;
  std::sort(values.begin(), values.end());
  band.median = values[values.size() / 2];
  const auto n = static_cast<double>(values.size());
  band.below = static_cast<double>(std::count_if(values.begin(), values.end(), [&](double v) { return v < low; })) / n;
  band.above = static_cast<double>(std::count_if(values.begin(), values.end(), [&](double v) { return v > high; })) / n;
  band.inside = 1.0 - band.below - band.above;
  return band;
}

/// The covariance of estimated pose `index` (stamp `stamp`): the file's line of the same index when its stamp
/// agrees (or always `by_index`: KITTI poses carry no stamps), else the nearest stamp within max_dt; nullptr when none.
const io::StampedCovariance* covariance_for(std::span<const io::StampedCovariance> covariances, std::size_t index, double stamp,
                                            double max_dt, bool by_index) {
  if (index < covariances.size() && (by_index || std::abs(covariances[index].stamp - stamp) <= max_dt)) return &covariances[index];
  if (by_index) return nullptr;
  const auto nearest = std::min_element(covariances.begin(), covariances.end(), [stamp](const auto& a, const auto& b) {
    return std::abs(a.stamp - stamp) < std::abs(b.stamp - stamp);
  });
  return nearest != covariances.end() && std::abs(nearest->stamp - stamp) <= max_dt ? &*nearest : nullptr;
}

/// e^T C^-1 e when C is positive definite.
std::optional<double> nees_of(const Eigen::VectorXd& e, const Eigen::MatrixXd& C) {
  const Eigen::LLT<Eigen::MatrixXd> llt(C);
  if (llt.info() != Eigen::Success || C.diagonal().minCoeff() <= 0.0) return std::nullopt;
  return e.dot(llt.solve(e));
}

}  // namespace

PoseNees evaluate_pose_nees(const TrajectoryReport& report, std::span<const io::StampedCovariance> covariances, const std::string& source,
                            std::span<const double> est_stamps) {
  PoseNees out;
  if (report.est.empty()) return out;
  // Start alignment: T_gt_0 T_est_0^-1 applied to every estimated pose.
  const SE3 T_align = report.gt.front() * report.est.front().inverse();
  std::vector<double> pose_values, translation_values;
  for (std::size_t i = 0; i < report.est.size(); ++i) {
    const std::size_t index = report.est_index[i];
    const double stamp = index < est_stamps.size() ? est_stamps[index] : report.stamps[i];
    const io::StampedCovariance* c = covariance_for(covariances, index, stamp, report.options.max_dt, report.options.associate_by_index);
    if (!c) {
      ++out.skipped;
      continue;
    }
    const SE3 T_est = T_align * report.est[i];
    const SE3& T_gt = report.gt[i];
    Vec6 e;
    e << T_gt.translation() - T_est.translation(), (T_est.inverse() * T_gt).log().tail<3>();
    const std::optional<double> pose = nees_of(e, c->covariance);
    const std::optional<double> translation = nees_of(e.head<3>(), c->covariance.topLeftCorner<3, 3>());
    if (!pose || !translation) {
      ++out.skipped;
      continue;
    }
    pose_values.push_back(*pose);
    translation_values.push_back(*translation);
    out.stamps.push_back(report.stamps[i]);
  }
  if (pose_values.empty())
    throw InputError(source, "stamps",
                     "no pose of the estimate has a covariance with a matching stamp (within --max-dt) that is positive definite");
  out.values = pose_values;
  out.pose = band_of(std::move(pose_values), kChi2Low6, kChi2High6);
  out.translation = band_of(std::move(translation_values), kChi2Low3, kChi2High3);
  return out;
}

}  // namespace mlidar::eval
