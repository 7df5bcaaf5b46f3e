#include "mlidar/slam/residuals.hpp"

#include <cmath>

namespace mlidar::slam {

void plane_residual(const PlaneCoefficients& plane, const Vec3& q_world, Vec3& residual, Mat36& jacobian) {
  const Vec3& w = plane.normal;
  residual = (w.dot(q_world) + plane.offset) * w;
  const Mat3 wwT = w * w.transpose();
  jacobian.leftCols<3>() = wwT;
  jacobian.rightCols<3>() = -wwT * hat(q_world);
}

PlaneRow plane_row(const PlaneCoefficients& plane, const Vec3& q_world) {
  const Vec3& w = plane.normal;
  PlaneRow row;
  row.residual = w.dot(q_world) + plane.offset;
  row.jacobian << w, q_world.cross(w);
  return row;
}

EdgePlanes edge_planes(const Vec3& point, const Vec3& direction, const Vec3& q_world) {
  const Vec3 u = direction.normalized();
  const Vec3 offset = q_world - point;
  Vec3 w1 = offset - u.dot(offset) * u;
  if (w1.norm() < 1e-9) w1 = u.unitOrthogonal();
  w1.normalize();
  const Vec3 w2 = u.cross(w1).normalized();
  EdgePlanes planes;
  planes.first = {w1, -w1.dot(point)};
  planes.second = {w2, -w2.dot(point)};
  return planes;
}

}  // namespace mlidar::slam
