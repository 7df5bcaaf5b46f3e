#include "mlidar/slam/odometry_window.hpp"

#include <stdexcept>
#include <utility>

#include "mlidar/slam/marginalization.hpp"

namespace mlidar::slam {
namespace {

void add_to_map(const SE3& T_world_base, const std::vector<Eigen::Vector3f>& points, VoxelMap& map) {
  std::vector<Eigen::Vector3f> world(points.size());
  transform_points(T_world_base, points, world);
  map.add(world);
}

}  // namespace

OdometryWindow::OdometryWindow(OdometryWindowConfig config, VoxelMap edge_map, VoxelMap plane_map)
    : config_(std::move(config)),
      edge_map_(std::move(edge_map)),
      plane_map_(std::move(plane_map)),
      state_(WindowState::make({}, {SE3::identity()}, 0, false)) {
  if (config_.size < 1 || config_.pivot < 1 || config_.pivot > config_.size)
    throw std::invalid_argument("OdometryWindow: expected size >= 1 and 1 <= pivot <= size");
}

OdometryWindowUpdate OdometryWindow::add(std::size_t frame, LidarFrameFeatures features, const SE3& T_world_base_odometry,
                                         const SE3& T_estimate_output) {
  // Start from the window's previous estimate moved by the odometry's relative motion.
  SE3 initial = T_world_base_odometry;
  if (last_odometry_pose_ && !entries_.empty())
    initial = state_.T_world_base.back() * (last_odometry_pose_->inverse() * T_world_base_odometry);
  last_odometry_pose_ = T_world_base_odometry;

  OdometryWindowUpdate update;
  const auto capacity = static_cast<std::size_t>(config_.size + 1);
  const auto pivot = static_cast<std::size_t>(config_.pivot);
  if (entries_.size() == capacity) {
    // Sec 4.7.5, eq 4.39-4.44: the pivot into the prior (it is fixed in the solves, a variable here), then the
    // shift; the frame at p moves to p - 1 and is the new pivot, settled.
    WindowState pivot_free = state_;
    pivot_free.pose_fixed[pivot - 1] = false;
    LinearPrior prior = marginalize_frame(problem_, pivot_free, static_cast<int>(pivot - 1), config_.solver.huber_delta_m);
    shift_window(problem_, state_, std::move(prior), initial);
    entries_.pop_front();
    entries_.push_back({frame, std::move(features), T_estimate_output});
    settle(pivot - 1);
    update.settled = reported(pivot - 1);
  } else {
    state_.T_world_base.push_back(initial);
    state_.pose_fixed.push_back(false);
    entries_.push_back({frame, std::move(features), T_estimate_output});
    if (entries_.size() <= pivot) {  // filling the fixed part: taken as given
      settle(entries_.size() - 1);
      update.settled = reported(entries_.size() - 1);
    }
  }
  update.correspondences = solve();
  update.latest = reported(entries_.size() - 1);
  update.prior_rank = static_cast<int>(problem_.prior.jacobian.rows());
  return update;
}

std::vector<WindowPose> OdometryWindow::unsettled() const {
  std::vector<WindowPose> poses;
  for (std::size_t i = 0; i < entries_.size(); ++i)
    if (!state_.pose_fixed[i]) poses.push_back(reported(i));
  return poses;
}

WindowPose OdometryWindow::reported(std::size_t index) const {
  return {entries_[index].frame, state_.T_world_base[index] * entries_[index].T_estimate_output};
}

void OdometryWindow::settle(std::size_t index) {
  state_.pose_fixed[index] = true;
  const SE3& T_world_base = state_.T_world_base[index];
  LidarFrameFeatures& features = entries_[index].features;
  add_to_map(T_world_base, features.edges, edge_map_);
  add_to_map(T_world_base, features.planes, plane_map_);
  const Eigen::Vector3f origin = T_world_base.translation().cast<float>();
  edge_map_.remove_far(origin, config_.local_map_radius_m);
  plane_map_.remove_far(origin, config_.local_map_radius_m);
  features = {};  // in the map now; a fixed frame carries no terms
}

std::size_t OdometryWindow::solve() {
  // Eq 4.22: the variable frames' features against the local map attached to the pivot, extrinsics fixed.
  problem_.planes.clear();
  problem_.edges.clear();
  const auto pivot = static_cast<std::size_t>(config_.pivot - 1);
  problem_.anchor = pivot < entries_.size() ? MapAnchor{static_cast<int>(pivot), state_.T_world_base[pivot]} : MapAnchor{};
  const MapView map{edge_map_, plane_map_, config_.registration};
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (state_.pose_fixed[i]) continue;
    const MapFit fit =
        add_map_correspondences(entries_[i].features, static_cast<int>(i), 0, state_.T_world_base[i], map, config_.gate_m, problem_);
    if (fit.planes + fit.edges < static_cast<std::size_t>(config_.min_correspondences)) {
      problem_.planes.clear();
      problem_.edges.clear();
      return 0;
    }
  }
  if (problem_.planes.empty() && problem_.edges.empty()) return 0;
  state_ = solve_window(problem_, state_, config_.solver).state;  // LM accepts only steps that lower the cost
  return problem_.planes.size() + problem_.edges.size();
}

}  // namespace mlidar::slam
