#pragma once
// MLOD's stage-2 geometry (thesis 6.5.2): a proposal's points in its canonical frame and the regression targets.
//   eq 6.12  p_n = T p ⊙ s
//   eq 6.13  T = [Rz(γ)ᵀ | −Rz(γ)ᵀ c], s = [1/l, 1/w, 1/h]: the proposal's centre c at the origin, its length along x
//   eq 6.14  u = [(x − x_p)/l_p, (y − y_p)/w_p, (z − z_p)/h_p, (l − l_p)/l_p, (w − w_p)/w_p, (h − h_p)/h_p,
//                 sin(γ − γ_p), cos(γ − γ_p)]
// The thesis writes eq 6.13's translation as [−x, −y, −z] after the rotation; rotating first and then subtracting the
// unrotated centre would not put the centre at the origin unless γ = 0, so T here is the rigid transform that does
// (its rotation applied to p − c). Centres are the boxes' geometric centres (io::Box3D holds the bottom centre: z + h/2).
#include <array>
#include <span>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/io/detection_labels.hpp"

namespace mlidar::detect {

/// eq 6.14's eight regression targets of a box relative to a proposal.
using Residual = std::array<double, 8>;

/// The box's geometric centre (io::Box3D keeps the bottom centre).
Vec3 box_centre(const io::Box3D& box);

/// eq 6.12-6.13: a point of the base frame in the proposal's canonical frame, scaled to its size: the proposal's
/// inside is [-1/2, 1/2]³.
Vec3 to_canonical(const Vec3& point, const io::Box3D& proposal);
/// The inverse of to_canonical.
Vec3 from_canonical(const Vec3& canonical, const io::Box3D& proposal);
std::vector<Vec3> to_canonical(std::span<const Vec3> points, const io::Box3D& proposal);

/// eq 6.14: the residual of `box` relative to `proposal` (sizes positive).
Residual encode(const io::Box3D& box, const io::Box3D& proposal);
/// The box that `encode` gives `residual` for; the yaw from atan2(sin, cos) (a regressed pair need not have unit
/// norm), wrapped to (-π, π].
io::Box3D decode(const Residual& residual, const io::Box3D& proposal);

}  // namespace mlidar::detect
