#include "mlidar/detect/proposal_points.hpp"

#include <cmath>
#include <stdexcept>

#include "mlidar/detect/box_coding.hpp"

namespace mlidar::detect {

ProposalPoints proposal_points(std::span<const Vec3> cloud, std::span<const double> uncertainty, const io::Box3D& proposal,
                               double margin_m) {
  if (!uncertainty.empty() && uncertainty.size() != cloud.size())
    throw std::invalid_argument("proposal_points: one uncertainty per point, or none");
  io::Box3D grown = proposal;
  grown.length += 2.0 * margin_m;
  grown.width += 2.0 * margin_m;
  grown.height += 2.0 * margin_m;
  grown.center_bottom.z() -= margin_m;
  ProposalPoints out;
  // Points beyond the grown box's circumscribed circle cannot be inside: a cheap test before the canonical frame.
  const double reach_squared = 0.25 * (grown.length * grown.length + grown.width * grown.width);
  const Vec3& centre = grown.center_bottom;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double dx = cloud[i].x() - centre.x(), dy = cloud[i].y() - centre.y();
    if (dx * dx + dy * dy > reach_squared) continue;
    const Vec3 in_grown = to_canonical(cloud[i], grown);
    if (std::abs(in_grown.x()) > 0.5 || std::abs(in_grown.y()) > 0.5 || std::abs(in_grown.z()) > 0.5) continue;
    out.canonical.push_back(to_canonical(cloud[i], proposal));
    out.uncertainty.push_back(uncertainty.empty() ? 0.0 : uncertainty[i]);
    out.indices.push_back(i);
  }
  return out;
}

}  // namespace mlidar::detect
