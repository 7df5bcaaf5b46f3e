#pragma once
// Vector residuals of the thesis (sec 4.6.1) for a base-frame point p under
// the pose T = T_world_base, q = R p + t:
//   plane (eq 4.7): r_H = a w,  a = w^T q + d           (3-vector)
//   edge  (eq 4.8): r_E = [r_H(Pi_1), r_H(Pi_2)]         (6-vector)
// where Pi_1's normal w1 is the direction from the line to the point and
// Pi_2's normal w2 = u x w1 is perpendicular to w1 and to the line direction u.
// Jacobians are taken for a left perturbation T <- Exp(delta) T with
// delta = [rho, phi] (mlidar's tangent order): dq/ddelta = [I, -[q]x], so
//   J_H = w w^T [I, -[q]x].
// Plane coefficients are held fixed while differentiating (as in the thesis:
// they come from the map, not from the pose).
#include <Eigen/Core>

#include "mlidar/core/se3.hpp"

namespace mlidar::slam {

using Mat36 = Eigen::Matrix<double, 3, 6>;

/// Plane w^T x + d = 0 with |w| = 1.
struct PlaneCoefficients {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;
};

/// Eq 4.7: residual and its Jacobian for the world point q = T p.
void plane_residual(const PlaneCoefficients& plane, const Vec3& q_world, Vec3& residual, Mat36& jacobian);

/// Eq 4.7 as one scalar row: r_H = a w with |w| = 1 gives J_H = w j and
/// r_H = w a, so J_H^T J_H = j^T j and J_H^T r_H = j^T a with
/// a = w^T q + d and j = [w^T, (q x w)^T]: the same normal equations at a
/// third of the cost (what scan-to-map registration accumulates).
struct PlaneRow {
  double residual = 0.0;         ///< a, signed distance
  Vec6 jacobian = Vec6::Zero();  ///< j^T
};
PlaneRow plane_row(const PlaneCoefficients& plane, const Vec3& q_world);

/// The two planes of eq 4.8 for a line through `point` along unit `direction`,
/// seen from q_world. When q lies on the line, w1 is any unit normal to it.
struct EdgePlanes {
  PlaneCoefficients first;   ///< normal along the projection from the line to q
  PlaneCoefficients second;  ///< normal = direction x first.normal
};
EdgePlanes edge_planes(const Vec3& point, const Vec3& direction, const Vec3& q_world);

/// Huber weight for a residual of norm `norm` (IRLS): 1 inside delta, delta / norm outside.
inline double huber_weight(double norm, double delta) { return norm <= delta ? 1.0 : delta / norm; }

}  // namespace mlidar::slam
