#pragma once
// Internal to the pose readers: a homogeneous matrix read from text becomes
// an SE3 only when its rotation block is close to a rotation.
#include <string>

#include "mlidar/core/se3.hpp"

namespace mlidar::io {

/// Largest |(R^T R - I)_ij| a file's rotation block may have before it is rejected.
inline constexpr double kMaxOrthonormalityError = 1e-3;

/// SE3::from_matrix (re-orthonormalised) after checking that the rotation is
/// within `tolerance` of orthonormal with determinant +1;
/// InputError naming `source` and `field` otherwise.
SE3 checked_rigid(const Mat4& matrix, const std::string& source, const std::string& field, double tolerance = kMaxOrthonormalityError);

}  // namespace mlidar::io
