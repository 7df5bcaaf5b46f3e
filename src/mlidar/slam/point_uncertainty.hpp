#pragma once
// Uncertainty-aware mapping (thesis sec 4.8): the covariance of every feature
// point, how it weights the registration and which points enter the map.
//
// A feature p_l of LiDAR l, seen from the base through the uncertain
// extrinsic T_base_lidar (alpha Xi, eq 4.24) and with the sensor's noise Z
// (range and bearing, core/pose_uncertainty.hpp), has in the base frame the
// covariance Sigma_b = H diag(alpha Xi, Z) H^T (eq 4.25-4.29). In the
// registration (eq 4.23) a plane row r = n^T q + d then has the variance
// n_b^T Sigma_b n_b beyond the map's own residual sigma_0, and is weighted by
//   w_ua = sigma_0^2 / (sigma_0^2 + n_b^T Sigma_b n_b),
// 1 for a certain point, so that a run without doubt is the unweighted one;
// far points and an auxiliary LiDAR with a doubtful extrinsic count less.
// A registered frame's points enter the map with the covariance through the
// LiDAR's world pose, compound(T_world_base with the registration's Xi_reg,
// T_base_lidar with alpha Xi) (fourth order, Barfoot & Furgale 2014); those
// with tr(Sigma) > w are dropped and the rest downsampled by eq 4.30.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/pose_uncertainty.hpp"

namespace mlidar::slam {

/// A symmetric 3x3 covariance (m^2) stored as its upper triangle: xx, xy, xz, yy, yz, zz.
struct PointCovariance {
  std::array<float, 6> upper{};

  static PointCovariance from(const Mat3& m);
  Mat3 matrix() const;
  double trace() const { return static_cast<double>(upper[0]) + upper[3] + upper[5]; }
  /// n^T Sigma n.
  double along(const Vec3& n) const;
};

/// `mapping:` in the config (thesis Table 4.2's w and alpha; alpha is window.extrinsic_covariance_scale).
struct UncertaintyConfig {
  bool enabled = false;  ///< mapping.uncertainty_aware
  /// w, m^2: a point whose covariance trace exceeds it does not enter the map (eq 4.30's threshold too).
  double trace_threshold_m2 = 0.1;
  /// sigma_0, m: a certain point's residual against the map (sensor noise and plane fit).
  double residual_sigma_m = 0.05;
  double range_sigma_m = 0.03;      ///< Z along the beam where the LiDAR model gives none
  double angular_sigma_rad = 1e-3;  ///< Z across the beam, per axis
  double voxel_filter_m = 0.2;      ///< eq 4.30's cube edge for a frame's points before they enter the map (0: off)
};

/// Eq 4.29 for each base-frame feature of one LiDAR: H diag(T_base_lidar.covariance, Z) H^T, Z from the point's
/// range and bearing seen from the LiDAR. T_base_lidar.covariance: left perturbation, base frame.
std::vector<PointCovariance> feature_covariances(std::span<const Eigen::Vector3f> points_base, const UncertainPose& T_base_lidar,
                                                 double range_sigma_m, double angular_sigma_rad);

/// The registration weight of a plane row with unit normal n_base (base frame) for a point of covariance `sigma`.
inline double uncertainty_weight(const PointCovariance& sigma, const Vec3& n_base, double residual_sigma_sq) {
  return residual_sigma_sq / (residual_sigma_sq + sigma.along(n_base));
}

/// A map point and its covariance (world frame).
struct CovariantPoint {
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  PointCovariance covariance;
  std::uint8_t source = 255;  ///< the LiDAR that saw it (its index), 255 when unknown
};

/// Eq 4.30: the points grouped by cubes of edge `cube_m` (> 0); each cube becomes one point
/// y = sum w_i y_i, Sigma = sum w_i^2 Sigma_i with w_i = (w - tr Sigma_i) / sum_j (w - tr Sigma_j).
/// Points with tr(Sigma) >= w carry no weight; a cube of only those is dropped. Output in the order each
/// cube's first point came; its source is that of the cube's heaviest point (the first of equals).
std::vector<CovariantPoint> covariance_voxel_filter(std::span<const CovariantPoint> points, double cube_m, double trace_threshold_m2);

}  // namespace mlidar::slam
