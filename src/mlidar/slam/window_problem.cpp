#include "mlidar/slam/window_problem.hpp"

#include <stdexcept>
#include <string>

namespace mlidar::slam {

WindowState WindowState::make(std::vector<SE3> poses, std::vector<SE3> extrinsics, int fixed_poses, bool calibrate) {
  WindowState state;
  state.pose_fixed.resize(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) state.pose_fixed[i] = static_cast<int>(i) < fixed_poses;
  state.T_world_base = std::move(poses);
  state.T_base_lidar = std::move(extrinsics);
  set_extrinsic_mode(state, calibrate ? ExtrinsicMode::kCalibrate : ExtrinsicMode::kFixed);
  return state;
}

const SE3& WindowState::value(VariableId id) const {
  return id.kind == VariableId::Kind::kPose ? T_world_base.at(static_cast<std::size_t>(id.index))
                                            : T_base_lidar.at(static_cast<std::size_t>(id.index));
}

SE3& WindowState::value(VariableId id) {
  return id.kind == VariableId::Kind::kPose ? T_world_base.at(static_cast<std::size_t>(id.index))
                                            : T_base_lidar.at(static_cast<std::size_t>(id.index));
}

bool WindowState::fixed(VariableId id) const {
  return id.kind == VariableId::Kind::kPose ? pose_fixed.at(static_cast<std::size_t>(id.index))
                                            : extrinsic_fixed.at(static_cast<std::size_t>(id.index));
}

void set_extrinsic_mode(WindowState& state, ExtrinsicMode mode) {
  state.extrinsic_fixed.assign(state.T_base_lidar.size(), mode == ExtrinsicMode::kFixed);
  if (!state.extrinsic_fixed.empty()) state.extrinsic_fixed[0] = true;
}

VariableLayout::VariableLayout(const WindowState& state) {
  pose_offset.assign(state.T_world_base.size(), -1);
  extrinsic_offset.assign(state.T_base_lidar.size(), -1);
  for (std::size_t i = 0; i < pose_offset.size(); ++i)
    if (!state.pose_fixed[i]) {
      pose_offset[i] = size;
      size += 6;
    }
  for (std::size_t j = 0; j < extrinsic_offset.size(); ++j)
    if (!state.extrinsic_fixed[j]) {
      extrinsic_offset[j] = size;
      size += 6;
    }
}

int VariableLayout::offset(VariableId id) const {
  const auto index = static_cast<std::size_t>(id.index);
  return id.kind == VariableId::Kind::kPose ? pose_offset.at(index) : extrinsic_offset.at(index);
}

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("window problem: " + what);
}

template <typename Correspondence>
void check_indices(const std::vector<Correspondence>& list, const WindowState& state, const char* kind) {
  for (const Correspondence& c : list)
    require(c.frame >= 0 && static_cast<std::size_t>(c.frame) < state.T_world_base.size() && c.lidar >= 0 &&
                static_cast<std::size_t>(c.lidar) < state.T_base_lidar.size(),
            std::string(kind) + " correspondence with frame " + std::to_string(c.frame) + " / lidar " + std::to_string(c.lidar) +
                " outside the window");
}

}  // namespace

SE3 map_motion(const MapAnchor& anchor, const WindowState& state) {
  if (anchor.frame < 0) return SE3::identity();
  return state.T_world_base.at(static_cast<std::size_t>(anchor.frame)) * anchor.T_world_base_reference.inverse();
}

void check_problem(const WindowProblem& problem, const WindowState& state) {
  require(state.pose_fixed.size() == state.T_world_base.size(), "pose_fixed size differs from the number of poses");
  require(state.extrinsic_fixed.size() == state.T_base_lidar.size(), "extrinsic_fixed size differs from the number of LiDARs");
  require(state.extrinsic_fixed.empty() || state.extrinsic_fixed[0], "the base LiDAR's extrinsic must be fixed");
  check_indices(problem.planes, state, "plane");
  check_indices(problem.edges, state, "edge");
  require(problem.anchor.frame >= -1 && problem.anchor.frame < static_cast<int>(state.T_world_base.size()),
          "map anchor " + std::to_string(problem.anchor.frame) + " outside the window");
  const LinearPrior& prior = problem.prior;
  require(prior.linearization_points.size() == prior.variables.size(), "prior linearization points differ from its variables");
  require(prior.jacobian.cols() == static_cast<Eigen::Index>(6 * prior.variables.size()) && prior.jacobian.rows() == prior.residual.size(),
          "prior Jacobian size");
  for (const VariableId& id : prior.variables) {
    const std::size_t count = id.kind == VariableId::Kind::kPose ? state.T_world_base.size() : state.T_base_lidar.size();
    require(id.index >= 0 && static_cast<std::size_t>(id.index) < count, "prior variable outside the window");
  }
}

}  // namespace mlidar::slam
