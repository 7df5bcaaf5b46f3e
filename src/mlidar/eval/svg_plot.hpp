#pragma once
// A small self-contained SVG writer for trajectory plots (no Python at run time):
// left panel, top view (x, y) of ground truth and aligned estimate with equal
// axis scales; right panel, ATE translation error over time.
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"

namespace mlidar::eval {

/// The SVG document. gt, est, stamps and ate_m have one entry per associated
/// pose (same length, at least 1). Long trajectories are thinned to at most
/// 4000 vertices per line so the file stays small.
std::string trajectory_plot_svg(const std::vector<SE3>& gt, const std::vector<SE3>& est, const std::vector<double>& stamps,
                                const std::vector<double>& ate_m);

}  // namespace mlidar::eval
