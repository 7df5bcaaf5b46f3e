// Thesis Fig 6.2's experiment (6.4.3): mean plane-fit error with and without the
// covariance weights over alpha in [0, 0.1], two planar patches, 100 trials of
// 10000 points each (eval/plane_fit_toy.hpp). Prints a markdown table for
// docs/benchmarks.md. Usage: plane_fit_toy_table [trials]
#include <cstdio>
#include <cstdlib>

#include "mlidar/core/conversions.hpp"
#include "mlidar/eval/plane_fit_toy.hpp"

int main(int argc, char** argv) {
  using namespace mlidar;
  const int trials = argc > 1 ? std::atoi(argv[1]) : 100;
  const eval::PlanarPatch ground{Vec3(12.0, 0.0, -1.8), Vec3::UnitX(), Vec3::UnitY(), 10.0, 10.0};
  const eval::PlanarPatch wall{Vec3(15.0, 0.0, 2.0), Vec3::UnitY(), Vec3::UnitZ(), 8.0, 3.0};
  std::printf("| alpha | ground: unweighted | ground: weighted | wall: unweighted | wall: weighted |\n|---|---|---|---|---|\n");
  for (int step = 0; step <= 10; ++step) {
    const double alpha = 0.01 * step;
    std::printf("| %.2f", alpha);
    for (const auto& patch : {ground, wall}) {
      eval::PlaneFitToySpec spec;
      spec.patch = patch;
      spec.T_base_lidar2 = SE3(quat_from_rpy_deg(Vec3(10.0, 10.0, 10.0)), Vec3(1.0, 1.0, 1.0));
      spec.alpha = alpha;
      spec.trials = trials;
      const eval::PlaneFitToyResult result = eval::run_plane_fit_toy(spec);
      std::printf(" | %.3g | %.3g", result.mean_error_unweighted, result.mean_error_weighted);
    }
    std::printf(" |\n");
  }
  return 0;
}
