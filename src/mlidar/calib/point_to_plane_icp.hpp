#pragma once
// Robust point-to-plane ICP (Chen & Medioni 1992; thesis 3.4.3.3 uses it for
// the refinement) of a source cloud against a RefSurface, Gauss-Newton on SE(3)
// with the left update T <- Exp(delta) T, delta = [rho, phi]:
//   r_i = n_i . (T p_i - q_i),  dr_i/d delta = [n_i^T, (T p_i x n_i)^T]
// and iteratively reweighted least squares with the Cauchy kernel
//   w_i = 1 / (1 + (r_i / c)^2).
// Coarse-to-fine: each level has its own source voxel size and correspondence
// distance. The result carries the information matrix H = J^T W J at the
// solution and the covariance s^2 H^-1, s^2 = sum w r^2 / (N - 6).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/calib/ref_surface.hpp"
#include "mlidar/core/se3.hpp"

namespace mlidar::calib {

struct IcpLevel {
  double voxel_size = 0.5;          ///< m, source downsampling (0 = keep every point)
  double max_correspondence = 1.0;  ///< m, farther nearest neighbours are not matched
  double kernel_scale = 0.2;        ///< m, c of the Cauchy kernel; |r| <= 3c is an inlier
};

struct IcpConfig {
  std::vector<IcpLevel> levels{{1.0, 2.0, 0.5}, {0.4, 0.8, 0.15}, {0.1, 0.2, 0.03}};
  int max_iterations = 30;              ///< per level
  std::size_t max_points = 20000;       ///< per level, more thinned source points are strided down to this
  double rotation_tolerance = 2e-4;     ///< rad: a smaller step ends the level
  double translation_tolerance = 1e-3;  ///< m
  std::size_t min_matches = 30;         ///< fewer matches: the registration fails
};

struct IcpResult {
  SE3 T_ref_source;
  Mat6 information = Mat6::Zero();  ///< J^T W J at the solution, [t, r] order
  Mat6 covariance = Mat6::Zero();   ///< s^2 H^-1 (zero when H is singular)
  double rmse = 0.0;                ///< m, of the inliers' point-to-plane residuals (last level)
  double inlier_ratio = 0.0;        ///< inliers / thinned source points (last level)
  std::size_t matches = 0;          ///< correspondences within max_correspondence (last level)
  int iterations = 0;               ///< over all levels
  bool converged = false;           ///< the last level's step fell below the tolerances
  bool enough_matches = true;
};

/// Registers `source` (in its own frame) to `surface` starting from T_ref_source.
/// Throws std::invalid_argument for a config with no level or a non-positive distance.
IcpResult point_to_plane_icp(RefSurface& surface, std::span<const Eigen::Vector3f> source, const SE3& T_ref_source,
                             const IcpConfig& config);

}  // namespace mlidar::calib
