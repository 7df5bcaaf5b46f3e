#pragma once
// Correspondence search against a voxel-hashed local map (thesis eq 4.7/4.8):
// the k nearest map points of a world point, fitted by PCA
//   plane: every neighbour within plane_tolerance_m of the plane and the
//          neighbours not colinear (middle eigenvalue >= plane_spread x smallest)
//          and spread across at least plane_min_extent_m (sqrt of the middle eigenvalue);
//   line:  largest eigenvalue >= edge_linearity x middle one and every
//          neighbour within edge_tolerance_m of the line.
// Shared by scan-to-map registration and the back end's window correspondences.
#include <array>
#include <optional>

#include <Eigen/Eigenvalues>

#include "mlidar/core/se3.hpp"
#include "mlidar/slam/residuals.hpp"
#include "mlidar/slam/scan_to_map.hpp"
#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {

/// A map line through `point` along the unit `direction` (world frame).
struct MapLine {
  Vec3 point = Vec3::Zero();
  Vec3 direction = Vec3::UnitX();
};

/// A neighbourhood's mean and the eigen-decomposition of its covariance (ascending eigenvalues, m^2).
struct Neighbourhood {
  Vec3 mean = Vec3::Zero();
  Eigen::SelfAdjointEigenSolver<Mat3> eigen;
};
/// Fits the first `count` of `points` (VoxelMap::nearest's output); false when the decomposition failed.
bool fit_neighbourhood(const std::array<Eigen::Vector3f, VoxelMap::kMaxNeighbors>& points, int count, Neighbourhood& out);

/// The plane of q_world's map neighbours within sqrt(search_radius_sq), or none.
std::optional<PlaneCoefficients> match_plane(const VoxelMap& plane_map, const Vec3& q_world, float search_radius_sq,
                                             const RegistrationConfig& config);
/// The line of q_world's map neighbours within sqrt(search_radius_sq), or none.
std::optional<MapLine> match_line(const VoxelMap& edge_map, const Vec3& q_world, float search_radius_sq, const RegistrationConfig& config);

}  // namespace mlidar::slam
