#include "mlidar/pipelines/doctor_motion.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "mlidar/core/conversions.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {

BaseMotion::BaseMotion(const io::SourceLidar& base)
    : odometry_(std::make_unique<slam::Odometry>(slam::OdometryConfig{},
                                                 std::vector<slam::LidarSetup>{{base.name, base.model, SE3::identity()}})) {}
BaseMotion::~BaseMotion() = default;
BaseMotion::BaseMotion(BaseMotion&&) noexcept = default;
BaseMotion& BaseMotion::operator=(BaseMotion&&) noexcept = default;

void BaseMotion::add(double stamp, const std::optional<Scan>& scan) {
  Frame frame{stamp, {scan.value_or(Scan{})}};
  if (!scan) frame.scans[0].stamp = stamp;
  const slam::FrameResult result = odometry_->process(frame);
  poses_.push_back(result.lost() ? std::nullopt : std::optional<SE3>(result.T_world_base));
}

MotionSummary BaseMotion::summary(double frame_period, const MotionCheckConfig& config) const {
  MotionSummary out;
  out.frames = poses_.size();
  out.registered = static_cast<std::size_t>(std::count_if(poses_.begin(), poses_.end(), [](const auto& p) { return p.has_value(); }));
  const auto step = static_cast<std::size_t>(std::max(1.0, std::round(config.pair_seconds / std::max(frame_period, 1e-9))));
  Mat3 scatter = Mat3::Zero();
  for (std::size_t k = 0; k + step < poses_.size(); ++k) {
    if (!poses_[k] || !poses_[k + step]) continue;
    ++out.pairs;
    const Vec3 rotation = (poses_[k]->inverse() * *poses_[k + step]).log().tail<3>();  // in the base frame at k
    const double degrees = rad_to_deg(rotation.norm());
    out.largest_turn_deg = std::max(out.largest_turn_deg, degrees);
    if (degrees < config.turn_deg) continue;
    ++out.turning_pairs;
    const Vec3 u = rotation.normalized();
    scatter += u * u.transpose();
  }
  if (out.turning_pairs >= 2) {
    const Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);  // ascending
    out.axis_spread = std::sqrt(std::max(0.0, eigen.eigenvalues()(1)) / eigen.eigenvalues()(2));
    out.main_axis = eigen.eigenvectors().col(2);
  }
  return out;
}

}  // namespace mlidar::pipelines
