#include "mlidar/slam/calibration_window.hpp"

#include "mlidar/slam/window_solver.hpp"

namespace mlidar::slam {

CalibrationWindowResult solve_calibration_window(std::span<const CalibrationFrame> frames, const SE3& T_base_lidar, const MapView& map,
                                                 std::span<const double> gates_m, double huber_delta_m) {
  CalibrationWindowResult result;
  result.T_base_lidar = T_base_lidar;
  std::vector<SE3> poses;
  for (const auto& frame : frames) poses.push_back(frame.T_world_base);
  // Eq 4.21 with every pose fixed; extrinsic 0 is the base (fixed), 1 this LiDAR.
  WindowState state = WindowState::make(poses, {SE3::identity(), T_base_lidar}, static_cast<int>(poses.size()), true);
  WindowSolverConfig solver;
  solver.huber_delta_m = huber_delta_m;
  for (const double gate : gates_m) {
    WindowProblem problem;
    result.fit = {};
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const SE3 T_world_lidar = frames[i].T_world_base * state.T_base_lidar[1];
      const MapFit one = add_map_correspondences(frames[i].features, static_cast<int>(i), 1, T_world_lidar, map, gate, problem);
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
  }
  result.solved = true;
  result.T_base_lidar = state.T_base_lidar[1];
  return result;
}

}  // namespace mlidar::slam
