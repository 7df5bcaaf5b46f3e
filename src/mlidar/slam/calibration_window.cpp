#include "mlidar/slam/calibration_window.hpp"

#include <stdexcept>

#include "mlidar/slam/window_solver.hpp"

namespace mlidar::slam {
namespace {

/// The passes to run: each gate once, then the last gate up to `settle_passes` more times.
std::vector<double> pass_gates(const CalibrationWindowOptions& options) {
  if (options.gates_m.empty()) throw std::invalid_argument("solve_calibration_window: no correspondence gates");
  std::vector<double> gates = options.gates_m;
  gates.insert(gates.end(), static_cast<std::size_t>(std::max(options.settle_passes, 0)), options.gates_m.back());
  return gates;
}

}  // namespace

CalibrationWindowResult solve_calibration_window(std::span<const CalibrationFrame> frames, const SE3& T_base_lidar, const MapView& map,
                                                 const CalibrationWindowOptions& options) {
  CalibrationWindowResult result;
  result.T_base_lidar = T_base_lidar;
  std::vector<SE3> poses;
  for (const auto& frame : frames) poses.push_back(frame.T_world_base);
  // Eq 4.21 with every pose fixed; extrinsic 0 is the base (fixed), 1 this LiDAR.
  WindowState state = WindowState::make(poses, {SE3::identity(), T_base_lidar}, static_cast<int>(poses.size()), true);
  WindowSolverConfig solver;
  solver.huber_delta_m = options.huber_delta_m;
  const std::vector<double> gates = pass_gates(options);
  for (std::size_t pass = 0; pass < gates.size(); ++pass) {
    const SE3 start = state.T_base_lidar[1];
    WindowProblem problem;
    result.fit = {};
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const SE3 T_world_lidar = frames[i].T_world_base * state.T_base_lidar[1];
      const MapFit one = add_map_correspondences(frames[i].features, static_cast<int>(i), 1, T_world_lidar, map, gates[pass], problem);
      result.fit.planes += one.planes;
      result.fit.edges += one.edges;
      result.fit.residual_sum_m += one.residual_sum_m;
    }
    if (problem.planes.size() + problem.edges.size() < 6) return result;
    const WindowSolution solution = solve_window(problem, state, solver);
    state = solution.state;
    result.information = solution.extrinsic_information[1];
    const double rows = static_cast<double>(problem.planes.size() + 2 * problem.edges.size());
    result.residual_variance_m2 = rows > 6.0 ? 2.0 * solution.final_cost / (rows - 6.0) : 0.0;
    const Vec6 step = (start.inverse() * state.T_base_lidar[1]).log();
    result.last_step_m = step.head<3>().norm();
    result.last_step_rad = step.tail<3>().norm();
    result.passes = static_cast<int>(pass) + 1;
    // Settled: re-matching at the last gate no longer moves the estimate.
    result.settled = result.last_step_m <= options.settle_translation_m && result.last_step_rad <= options.settle_rotation_rad;
    if (pass + 1 >= options.gates_m.size() && result.settled) break;
  }
  result.solved = true;
  result.T_base_lidar = state.T_base_lidar[1];
  return result;
}

}  // namespace mlidar::slam
