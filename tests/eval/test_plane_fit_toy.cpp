// Thesis 6.4.3: the weighted plane fit (W = 1 / tr(Xi)) beats the unweighted
// one once the second LiDAR's extrinsic is perturbed, and both agree without
// perturbation; the least-squares fit itself is exact on exact points.
#include <gtest/gtest.h>

#include "mlidar/core/conversions.hpp"
#include "mlidar/eval/plane_fit_toy.hpp"

namespace mlidar::eval {
namespace {

PlaneFitToySpec short_toy(double alpha) {
  PlaneFitToySpec spec;
  spec.patch = {Vec3(12.0, 0.0, -1.8), Vec3::UnitX(), Vec3::UnitY(), 10.0, 10.0};
  spec.T_base_lidar2 = SE3(quat_from_rpy_deg(Vec3(10.0, 10.0, 10.0)), Vec3(1.0, 1.0, 1.0));
  spec.alpha = alpha;
  spec.points = 2000;
  spec.trials = 30;
  spec.seed = 4;
  return spec;
}

TEST(PlaneFitToy, LeastSquaresIsExactOnExactPointsAndIgnoresZeroWeights) {
  // The plane z = -2: x = n / d = (0, 0, -0.5).
  std::vector<Vec3> points{{1, 0, -2}, {0, 1, -2}, {3, -2, -2}, {-4, 5, -2}, {7, 7, 9}};
  std::vector<double> weights{1.0, 2.0, 1.0, 0.5, 0.0};  // the last point is off the plane, weight 0
  EXPECT_LT((fit_plane_coefficients(points, weights) - Vec3(0, 0, -0.5)).norm(), 1e-12);
  weights.back() = 1.0;
  EXPECT_GT((fit_plane_coefficients(points, weights) - Vec3(0, 0, -0.5)).norm(), 0.01);
}

TEST(PlaneFitToy, WeightsHelpOncePerturbedAsInFig62) {
  const PlaneFitToyResult clean = run_plane_fit_toy(short_toy(0.0));
  // Without perturbation every point has the same tr(Xi): the two fits are the same fit.
  EXPECT_NEAR(clean.mean_error_weighted, clean.mean_error_unweighted, 1e-9);
  for (const double alpha : {0.02, 0.06, 0.1}) {
    const PlaneFitToyResult toy = run_plane_fit_toy(short_toy(alpha));
    EXPECT_LT(toy.mean_error_weighted, 0.5 * toy.mean_error_unweighted) << "alpha " << alpha;
    // The weighted fit leans on the base LiDAR's half: it stays near the clean error.
    EXPECT_LT(toy.mean_error_weighted, 3.0 * clean.mean_error_unweighted) << "alpha " << alpha;
  }
  EXPECT_GT(run_plane_fit_toy(short_toy(0.1)).mean_error_unweighted, run_plane_fit_toy(short_toy(0.02)).mean_error_unweighted);
}

}  // namespace
}  // namespace mlidar::eval
