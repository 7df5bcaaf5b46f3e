#pragma once
// Stage 2's input (thesis 6.5.2): the points around a proposal, in its canonical frame (eq 6.12-6.13), each with the
// trace of its covariance tr(Ξ) from the extrinsic perturbation (eq 6.7). The thesis enlarges each proposal by a
// margin (2 m) so that a proposal that is too small or shifted still holds the whole object.
#include <span>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/io/detection_labels.hpp"

namespace mlidar::detect {

struct ProposalPoints {
  std::vector<Vec3> canonical;       ///< eq 6.12: the proposal's inside is [-1/2, 1/2]³
  std::vector<double> uncertainty;   ///< tr(Ξ) of each point, m²
  std::vector<std::size_t> indices;  ///< into the cloud
};

/// The points of `cloud` inside `proposal` grown by `margin_m` on every side (length, width and height), with their
/// `uncertainty` (one per point, or empty for none: zeros), in cloud order.
ProposalPoints proposal_points(std::span<const Vec3> cloud, std::span<const double> uncertainty, const io::Box3D& proposal,
                               double margin_m = 2.0);

}  // namespace mlidar::detect
