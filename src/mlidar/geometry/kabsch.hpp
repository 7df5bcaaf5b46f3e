#pragma once
// Rotation that best maps one set of directions onto another (Kabsch 1976;
// thesis eq 2.6): R = argmin sum_i w_i |dst_i - R src_i|^2 over SO(3), no
// centring (directions, not points; for point sets see eval/alignment.hpp).
#include <span>

#include "mlidar/core/so3.hpp"

namespace mlidar {

/// H = sum w_i src_i dst_i^T = U S V^T, R = V diag(1, 1, det(V U^T)) U^T.
/// Precondition (asserted): equal sizes. Unique when the directions span at
/// least a plane (two non-parallel pairs).
Mat3 kabsch_rotation(std::span<const Vec3> src, std::span<const Vec3> dst);

}  // namespace mlidar
