// Plane fit, sequential RANSAC and Kabsch on directions against analytic answers.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/geometry/kabsch.hpp"
#include "mlidar/geometry/plane_ransac.hpp"

namespace mlidar {
namespace {

TEST(PlaneFit, PointsOnAPlaneGiveItsNormalAndOffset) {
  const Vec3 normal = Vec3(1, -2, 0.5).normalized();
  const Vec3 a = normal.unitOrthogonal();
  const Vec3 b = normal.cross(a);
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint32_t> indices;
  for (int i = 0; i < 50; ++i) {
    points.push_back((-0.5 * normal + (i % 7) * 0.3 * a + (i / 7) * 0.2 * b).cast<float>());
    indices.push_back(static_cast<std::uint32_t>(i));
  }
  const PlaneFit fit = fit_plane(points, indices);
  EXPECT_NEAR(std::abs(fit.plane.normal.dot(normal)), 1.0, 1e-6);
  EXPECT_NEAR(std::abs(fit.plane.offset), 0.5, 1e-6);
  EXPECT_LT(fit.rms(), 1e-6);
}

TEST(PlaneFit, CovarianceMatchesTheScatterOfRepeatedFits) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<std::uint32_t> indices(400);
  for (std::uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;
  double offset_var = 0.0;
  double predicted = 0.0;
  const int trials = 300;
  for (int t = 0; t < trials; ++t) {
    std::vector<Eigen::Vector3f> points;
    for (std::size_t i = 0; i < indices.size(); ++i) points.emplace_back(u(rng) + 1.0, u(rng), 2.0 + noise(rng));
    PlaneFit fit = fit_plane(points, indices);
    if (fit.plane.normal.z() < 0) fit.plane = fit.plane.flipped();
    offset_var += std::pow(fit.plane.offset + 2.0, 2) / trials;
    predicted += fit.covariance(3, 3) / trials;
  }
  EXPECT_NEAR(offset_var / predicted, 1.0, 0.25);
}

TEST(PlaneRansac, FindsThreePlanesAmongOutliersAndIsSeeded) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<float> u(0.F, 5.F);
  std::normal_distribution<float> noise(0.F, 0.02F);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 3000; ++i) {
    const int which = i % 3;
    Eigen::Vector3f p(u(rng), u(rng), u(rng));
    p(which) = noise(rng);  // planes x = 0, y = 0, z = 0
    points.push_back(p);
  }
  for (int i = 0; i < 600; ++i) points.emplace_back(u(rng) - 1.F, u(rng) - 1.F, u(rng) - 1.F);
  PlaneRansacConfig config;
  config.inlier_distance = 0.08;
  config.max_planes = 3;
  const auto planes = extract_planes(points, config);
  ASSERT_EQ(planes.size(), 3U);
  std::vector<int> axes;
  for (const auto& plane : planes) {
    int axis = 0;
    plane.fit.plane.normal.cwiseAbs().maxCoeff(&axis);
    axes.push_back(axis);
    EXPECT_GT(std::abs(plane.fit.plane.normal(axis)), 0.999);
    EXPECT_LT(std::abs(plane.fit.plane.offset), 0.01);
    EXPECT_GE(plane.inliers.size(), 950U);
  }
  std::sort(axes.begin(), axes.end());
  EXPECT_EQ(axes, (std::vector<int>{0, 1, 2}));
  const auto again = extract_planes(points, config);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(again[i].inliers, planes[i].inliers);
}

TEST(Kabsch, RecoversARotationFromThreeDirectionsAndNeverReflects) {
  const Mat3 R = (Eigen::AngleAxisd(2.5, Vec3(1, 2, -1).normalized())).toRotationMatrix();
  const std::vector<Vec3> src{Vec3(1, 0, 0), Vec3(0.3, 1, 0).normalized(), Vec3(0.1, 0.2, 1).normalized()};
  std::vector<Vec3> dst;
  for (const Vec3& v : src) dst.push_back(R * v);
  EXPECT_LT((kabsch_rotation(src, dst) - R).norm(), 1e-12);
  std::vector<Vec3> mirrored = dst;
  for (Vec3& v : mirrored) v.z() = -v.z();
  EXPECT_NEAR(kabsch_rotation(src, mirrored).determinant(), 1.0, 1e-12);
}

}  // namespace
}  // namespace mlidar
