#include "mlidar/detect/box_coding.hpp"

#include <cmath>
#include <numbers>

namespace mlidar::detect {
namespace {

/// Rz(γ)ᵀ v: v in the frame turned by γ about z.
Vec3 unrotate(const Vec3& v, double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {c * v.x() + s * v.y(), -s * v.x() + c * v.y(), v.z()};
}

Vec3 rotate(const Vec3& v, double yaw) { return unrotate(v, -yaw); }

double wrap_angle(double angle) {
  const double wrapped = std::remainder(angle, 2.0 * std::numbers::pi);
  return wrapped <= -std::numbers::pi ? wrapped + 2.0 * std::numbers::pi : wrapped;
}

}  // namespace

Vec3 box_centre(const io::Box3D& box) { return box.center_bottom + Vec3(0.0, 0.0, 0.5 * box.height); }

Vec3 to_canonical(const Vec3& point, const io::Box3D& proposal) {
  const Vec3 local = unrotate(point - box_centre(proposal), proposal.yaw);  // T p, eq 6.13
  return local.cwiseQuotient(Vec3(proposal.length, proposal.width, proposal.height));  // ⊙ s, eq 6.12
}

Vec3 from_canonical(const Vec3& canonical, const io::Box3D& proposal) {
  const Vec3 local = canonical.cwiseProduct(Vec3(proposal.length, proposal.width, proposal.height));
  return rotate(local, proposal.yaw) + box_centre(proposal);
}

std::vector<Vec3> to_canonical(std::span<const Vec3> points, const io::Box3D& proposal) {
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const Vec3& p : points) out.push_back(to_canonical(p, proposal));
  return out;
}

Residual encode(const io::Box3D& box, const io::Box3D& proposal) {
  const Vec3 d = box_centre(box) - box_centre(proposal);
  const double dyaw = box.yaw - proposal.yaw;
  return {d.x() / proposal.length,
          d.y() / proposal.width,
          d.z() / proposal.height,
          (box.length - proposal.length) / proposal.length,
          (box.width - proposal.width) / proposal.width,
          (box.height - proposal.height) / proposal.height,
          std::sin(dyaw),
          std::cos(dyaw)};
}

io::Box3D decode(const Residual& u, const io::Box3D& proposal) {
  io::Box3D box;
  box.length = proposal.length * (1.0 + u[3]);
  box.width = proposal.width * (1.0 + u[4]);
  box.height = proposal.height * (1.0 + u[5]);
  box.yaw = wrap_angle(proposal.yaw + std::atan2(u[6], u[7]));
  const Vec3 centre = box_centre(proposal) + Vec3(u[0] * proposal.length, u[1] * proposal.width, u[2] * proposal.height);
  box.center_bottom = centre - Vec3(0.0, 0.0, 0.5 * box.height);
  return box;
}

}  // namespace mlidar::detect
