// Residuals (eq 4.7/4.8) and their Jacobians against central differences; the voxel map against brute force.
#include <random>

#include <gtest/gtest.h>

#include "mlidar/slam/residuals.hpp"
#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {
namespace {

/// Central-difference Jacobian of f(Exp(delta) T) at delta = 0.
template <typename F>
Eigen::MatrixXd numeric_jacobian(const F& f, const SE3& T) {
  const double h = 1e-6;
  const Eigen::VectorXd f0 = f(T);
  Eigen::MatrixXd J(f0.size(), 6);
  for (int k = 0; k < 6; ++k) {
    Vec6 d = Vec6::Zero();
    d(k) = h;
    J.col(k) = (f(SE3::exp(d) * T) - f(SE3::exp(-d) * T)) / (2.0 * h);
  }
  return J;
}

TEST(Residuals, PlaneJacobianMatchesNumeric) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const PlaneCoefficients plane{Vec3(n(rng), n(rng), n(rng)).normalized(), n(rng) * 5.0};
    const SE3 T(so3_exp(Vec3(n(rng), n(rng), n(rng))), Vec3(n(rng), n(rng), n(rng)) * 10.0);
    const Vec3 p = Vec3(n(rng), n(rng), n(rng)) * 20.0;
    Vec3 r;
    Mat36 J;
    plane_residual(plane, T * p, r, J);
    EXPECT_NEAR(r.norm(), std::abs(plane.normal.dot(T * p) + plane.offset), 1e-9);  // |r| = point-plane distance
    const auto f = [&](const SE3& X) {
      Vec3 rr;
      Mat36 JJ;
      plane_residual(plane, X * p, rr, JJ);
      return Eigen::VectorXd(rr);
    };
    EXPECT_LT((numeric_jacobian(f, T) - J).norm(), 1e-5 * (1.0 + J.norm())) << trial;
  }
}

TEST(Residuals, PlaneRowGivesTheVectorResidualsNormalEquations) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const PlaneCoefficients plane{Vec3(n(rng), n(rng), n(rng)).normalized(), n(rng) * 5.0};
    const Vec3 q = Vec3(n(rng), n(rng), n(rng)) * 20.0;
    Vec3 r;
    Mat36 J;
    plane_residual(plane, q, r, J);
    const PlaneRow row = plane_row(plane, q);
    EXPECT_NEAR(std::abs(row.residual), r.norm(), 1e-12);
    const Mat6 H_vector = J.transpose() * J, H_row = row.jacobian * row.jacobian.transpose();
    EXPECT_LT((H_vector - H_row).norm(), 1e-10 * (1.0 + H_vector.norm())) << trial;
    EXPECT_LT((J.transpose() * r - row.jacobian * row.residual).norm(), 1e-10 * (1.0 + (J.transpose() * r).norm())) << trial;
  }
}

TEST(Residuals, EdgeResidualIsDistanceToLineAndJacobianMatches) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 a(n(rng), n(rng), n(rng));
    const Vec3 u = Vec3(n(rng), n(rng), n(rng)).normalized();
    const SE3 T(so3_exp(Vec3(n(rng), n(rng), n(rng))), Vec3(n(rng), n(rng), n(rng)));
    const Vec3 p = Vec3(n(rng), n(rng), n(rng)) * 5.0;
    const Vec3 q = T * p;
    const EdgePlanes planes = edge_planes(a, u, q);
    EXPECT_NEAR(planes.first.normal.dot(u), 0.0, 1e-12);
    EXPECT_NEAR(planes.second.normal.dot(u), 0.0, 1e-12);
    EXPECT_NEAR(planes.first.normal.dot(planes.second.normal), 0.0, 1e-12);
    const auto f = [&](const SE3& X) {
      Eigen::VectorXd r(6);
      Vec3 r1;
      Mat36 J1;
      plane_residual(planes.first, X * p, r1, J1);
      r.head<3>() = r1;
      plane_residual(planes.second, X * p, r1, J1);
      r.tail<3>() = r1;
      return r;
    };
    const double line_distance = ((q - a) - u.dot(q - a) * u).norm();
    EXPECT_NEAR(f(T).norm(), line_distance, 1e-9);
    Eigen::MatrixXd J(6, 6);
    Vec3 r1;
    Mat36 J1;
    plane_residual(planes.first, q, r1, J1);
    J.topRows<3>() = J1;
    plane_residual(planes.second, q, r1, J1);
    J.bottomRows<3>() = J1;
    EXPECT_LT((numeric_jacobian(f, T) - J).norm(), 1e-5 * (1.0 + J.norm())) << trial;
  }
}

TEST(Residuals, HuberWeight) {
  EXPECT_DOUBLE_EQ(huber_weight(0.05, 0.1), 1.0);
  EXPECT_DOUBLE_EQ(huber_weight(0.4, 0.1), 0.25);
}

TEST(VoxelMap, NearestMatchesBruteForceWithinOneVoxel) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(-5.0F, 5.0F);
  std::vector<Eigen::Vector3f> points(3000);
  for (auto& p : points) p = {u(rng), u(rng), u(rng)};
  VoxelMap map(1.0, 1000);
  map.add(points);
  EXPECT_EQ(map.points().size(), points.size());
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Vector3f q(u(rng), u(rng), u(rng));
    std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors> near;
    const float radius_sq = 1.0F;  // within one voxel, the 27-voxel search is exact
    const int count = map.nearest(q, 5, radius_sq, near);
    std::vector<float> brute;
    for (const auto& p : points)
      if ((p - q).squaredNorm() <= radius_sq) brute.push_back((p - q).squaredNorm());
    std::sort(brute.begin(), brute.end());
    ASSERT_EQ(count, static_cast<int>(std::min<std::size_t>(5, brute.size())));
    for (int k = 0; k < count; ++k)
      EXPECT_FLOAT_EQ((near[static_cast<std::size_t>(k)] - q).squaredNorm(), brute[static_cast<std::size_t>(k)]);
  }
}

TEST(VoxelMap, NearestMatchesBruteForceForEveryKAndRadius) {
  // Points on three planes through a 4 m cube (as a map of plane features), queries near them and near voxel faces.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> u(-2.0F, 2.0F);
  std::normal_distribution<float> noise(0.0F, 0.02F);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 900; ++i) {  // sparse: the k-th neighbour is often in the far layer of some axis
    const float a = u(rng), b = u(rng), n = noise(rng);
    points.push_back(i % 3 == 0   ? Eigen::Vector3f(a, b, n)
                     : i % 3 == 1 ? Eigen::Vector3f(n + 1.0F, a, b)
                                  : Eigen::Vector3f(a, n - 0.5F, b));
  }
  for (int i = 0; i < 200; ++i) points.emplace_back(u(rng), u(rng), u(rng));  // scattered: neighbours in the corners too
  const double voxel = 0.5;
  VoxelMap map(voxel, 10000);
  map.add(points);
  for (int trial = 0; trial < 300; ++trial) {
    Eigen::Vector3f q =
        points[static_cast<std::size_t>(trial * 13) % points.size()] + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)) * 5.0F;
    if (trial % 4 == 0) q.x() = std::round(q.x() / 0.5F) * 0.5F + noise(rng) * 0.05F;  // by a voxel face
    const int k = 1 + trial % VoxelMap::kMaxNeighbors;
    const float radius_sq = trial % 2 == 0 ? 0.25F : 0.01F;  // at most one voxel: the 27-voxel search is exact
    std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors> near;
    const int count = map.nearest(q, k, radius_sq, near);
    std::vector<float> brute;
    for (const auto& p : points)
      if ((p - q).squaredNorm() <= radius_sq) brute.push_back((p - q).squaredNorm());
    std::sort(brute.begin(), brute.end());
    ASSERT_EQ(count, static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(k), brute.size()))) << "trial " << trial;
    for (int i = 0; i < count; ++i)
      EXPECT_EQ((near[static_cast<std::size_t>(i)] - q).squaredNorm(), brute[static_cast<std::size_t>(i)])
          << "trial " << trial << " neighbour " << i;
  }
}

TEST(VoxelMap, NearestFindsALonePointInEachOfTheTwentySixNeighbours) {
  for (const float shift : {-0.2F, 0.0F, 0.2F}) {  // the query left of, at and right of its voxel's middle
    const Eigen::Vector3f q = Eigen::Vector3f::Constant(0.5F + shift);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          // The point of the neighbour's box nearest q, 5 cm inside it: within 1 m of q for every neighbour.
          const auto inside = [](int offset, float coordinate) { return offset < 0 ? -0.05F : offset > 0 ? 1.05F : coordinate; };
          const Eigen::Vector3f p(inside(dx, q.x()), inside(dy, q.y()), inside(dz, q.z()));
          VoxelMap map(1.0, 20);
          map.add(std::vector<Eigen::Vector3f>{p});
          std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors> near;
          const float radius_sq = (p - q).squaredNorm() + 1e-4F;
          ASSERT_EQ(map.nearest(q, 3, radius_sq, near), 1) << dx << " " << dy << " " << dz << " shift " << shift;
          EXPECT_EQ(near[0], p);
        }
  }
}

TEST(VoxelMap, AVoxelAddedAfterARemovalHoldsOnlyItsOwnPoints) {
  VoxelMap map(1.0, 4);
  map.add(
      std::vector<Eigen::Vector3f>{{0.5F, 0.5F, 0.5F}, {0.6F, 0.5F, 0.5F}, {20.5F, 0.5F, 0.5F}, {20.6F, 0.5F, 0.5F}, {20.7F, 0.5F, 0.5F}});
  map.remove_far(Eigen::Vector3f::Zero(), 10.0);  // the voxel at x = 20 goes
  map.add(std::vector<Eigen::Vector3f>{{-3.5F, 0.5F, 0.5F}, {0.7F, 0.5F, 0.5F}});
  std::vector<Eigen::Vector3f> kept = map.points();
  std::sort(kept.begin(), kept.end(), [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return a.x() < b.x(); });
  ASSERT_EQ(kept.size(), 4U);
  EXPECT_EQ(kept[0], Eigen::Vector3f(-3.5F, 0.5F, 0.5F));
  EXPECT_EQ(kept[1], Eigen::Vector3f(0.5F, 0.5F, 0.5F));
  EXPECT_EQ(kept[3], Eigen::Vector3f(0.7F, 0.5F, 0.5F));
  std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors> near;
  ASSERT_EQ(map.nearest({-3.5F, 0.5F, 0.5F}, 3, 1.0F, near), 1);  // the new voxel: its own point, none of the removed
  EXPECT_EQ(map.voxels(), 2U);
}

TEST(VoxelMap, BoundsPointsPerVoxelAndRemovesFarVoxels) {
  VoxelMap map(1.0, 3);
  std::vector<Eigen::Vector3f> same(10, Eigen::Vector3f(0.5F, 0.5F, 0.5F));
  same.push_back({50.5F, 0.5F, 0.5F});
  map.add(same);
  EXPECT_EQ(map.points().size(), 4u);
  map.remove_far(Eigen::Vector3f::Zero(), 10.0);
  EXPECT_EQ(map.voxels(), 1u);
  EXPECT_THROW(VoxelMap(0.0, 3), std::invalid_argument);
}

}  // namespace
}  // namespace mlidar::slam
