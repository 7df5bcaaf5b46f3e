#pragma once
// Scan-to-map registration of base-frame features against the local maps
// (thesis eq 4.9 with the residuals of eq 4.7/4.8, Huber loss), solved by
// iteratively reweighted Gauss-Newton on SE(3) with the left update
// T <- Exp(delta) T. Correspondences are re-found every iteration (see
// rematch_distance_m for the exception): a plane
// point takes its k nearest plane-map points within
// max(max_correspondence_m, neighborhood_radius_m) (the search radius follows
// the map's density; the pose uncertainty gates the residual instead: a
// correspondence is kept when |r| <= max_correspondence_m) (PCA: a plane when every
// neighbour lies within plane_tolerance of it and they are not colinear), an edge point its k nearest
// edge-map points (a line when the largest eigenvalue exceeds
// edge_linearity x the middle one and every neighbour lies within
// edge_tolerance of the line); a feature that moved less than
// rematch_distance_m since its last search keeps its fitted plane or line. Normal equations are summed with
// tbb::parallel_deterministic_reduce (fixed chunks: the same sums whatever the thread count). Degeneracy (Zhang, Kaess & Singh, ICRA 2016):
// the translation block of H is sum w n n^T over the residual normals; when the ratio of its smallest to largest eigenvalue (scale-free:
// independent of the number of points) falls below degeneracy_threshold, the update along the smallest one's eigenvector is dropped (the
// prediction is kept there) and the result says so.
// Feature selection (feature_selection.hpp, thesis Algorithm 2), when on: the
// first linearisation screens every feature at the start (its correspondence
// and information Lambda_i); the chosen ones, with their cached matches, are
// the only features of the remaining iterations.
#include <span>
#include <vector>

#include <optional>

#include <Eigen/Core>

#include "mlidar/core/se3.hpp"
#include "mlidar/slam/deskew.hpp"
#include "mlidar/slam/feature_selection.hpp"
#include "mlidar/slam/point_uncertainty.hpp"
#include "mlidar/slam/voxel_map.hpp"

namespace mlidar::slam {

struct RegistrationConfig {
  int max_iterations = 30;
  double convergence_translation_m = 1e-4;
  double convergence_rotation_rad = 1e-5;
  int neighbors = 5;
  /// A plane is fitted to its `neighbors` nearest map points and to up to this many (<= VoxelMap::kMaxNeighbors)
  /// when the extra ones lie within plane_extra_radius_m of the query: a dense map's extra neighbours average
  /// the noise of the fit, a sparse map's would bend it over a curved or stepped surface. Measured 2026-12-07
  /// (docs/benchmarks.md "More neighbours for the plane fit"): 8 within 0.5 m takes real Ouster keyframes' pair
  /// rotation median from 0.056 to 0.041 deg, but moves simulated 16-beam rigs' ATE by -6 to +20 % and
  /// `calibrate auto` on short handheld runs either way; so 5 here, and the odometry sets
  /// OdometryConfig::voxel_plane_neighbors_max (8) for frames of voxel samples.
  int plane_neighbors_max = 5;
  double plane_extra_radius_m = 0.5;
  double neighborhood_radius_m = 1.0;  ///< map neighbours are searched at least this far (the map's density, not the pose error)
  double plane_tolerance_m = 0.2;
  double huber_delta_m = 0.1;  ///< Huber scale on |r| (eq 4.9's rho)
  double plane_spread = 3.0;   ///< a plane needs middle eigenvalue >= this x smallest
  /// A plane needs its neighbours spread at least this far across (m, the square root of the middle eigenvalue of
  /// their covariance). Range noise lies along the beams: a patch narrower than it (a few points of one scan
  /// line) gets its normal from the noise, not the surface. The odometry sets it from its LiDARs' range noise
  /// (OdometryConfig::plane_min_extent_sigmas); 0 leaves it unchecked.
  double plane_min_extent_m = 0.0;
  double edge_linearity = 10.0;
  double edge_tolerance_m = 0.1;  ///< every edge neighbour within this of the fitted line
  /// Measured (rv rig, 40 frames each): campus 0.19-0.35, corridor 0.03-0.05.
  double degeneracy_threshold = 0.1;
  /// A feature's map neighbours are searched again only after it moved this far
  /// (world) since its last search; closer, the last fit (plane or line) is reused
  /// and only the residual re-evaluated. 0 searches every iteration.
  double rematch_distance_m = 0.02;
  SelectionConfig selection;  ///< good features (thesis Ch. 5); off by default
};

/// What the feature selection screened and kept (RegistrationResult::selection).
struct SelectionReport {
  SelectionMethod method = SelectionMethod::kNone;
  std::size_t screened = 0;          ///< features whose correspondence was searched at the start (drawn)
  std::size_t screened_matches = 0;  ///< of those, the ones with a correspondence
  std::size_t budget = 0;            ///< M
  double log_det_selected = 0.0;     ///< log det Lambda(S)
  bool stopped_by_time = false;
  double seconds = 0.0;  ///< screening and choosing
  /// The check of the result on features it did not use: a sample of the
  /// others, searched at the final pose (their mean |r| and matched share).
  std::size_t held_out = 0;
  std::size_t held_out_matches = 0;
  double held_out_mean_residual_m = 0.0;
  /// The held-out features disagreed, so the registration ran again on every
  /// feature (the result is that one's; `chosen` then holds every query).
  bool fell_back = false;
  /// The chosen features' positions among the queries (edges, then planes), ascending.
  std::vector<std::uint32_t> chosen;
};

struct RegistrationResult {
  SE3 T_world_base;
  bool converged = false;
  int iterations = 0;
  std::size_t queries = 0;
  std::size_t plane_matches = 0;
  std::size_t edge_matches = 0;
  double mean_residual_m = 0.0;            ///< mean |r| over matches at the last linearisation
  Mat6 hessian = Mat6::Zero();             ///< J^T W J at the solution, [t, r] order
  Vec6 eigenvalues = Vec6::Zero();         ///< of hessian, ascending
  double translation_observability = 0.0;  ///< lambda_min(H_tt) / lambda_max(H_tt), in [0, 1]
  bool degenerate = false;
  /// When degenerate: the unit translation (world frame) left at its initial value; zero otherwise.
  Vec3 weak_translation = Vec3::Zero();
  /// |r| of each query (edges, then planes, in the order given) at the last
  /// linearisation; NaN where it had no correspondence within the gate.
  std::vector<float> residuals_m;
  std::optional<BodyVelocity> velocity_used;  ///< with MotionDeskew: the features' final deskew velocity
  /// With feature selection: plane_matches and edge_matches count the chosen
  /// features only, and residuals_m is NaN for the others.
  std::optional<SelectionReport> selection;

  /// The share of the queries matched at the end. With selection: the chosen
  /// features' share times the share of all queries that matched at the start
  /// (the chosen are a sample of the drawn ones), so a frame that matched poorly stays poor.
  double match_ratio() const {
    if (queries == 0) return 0.0;
    const auto matched = static_cast<double>(plane_matches + edge_matches);
    if (!selection || selection->fell_back) return matched / static_cast<double>(queries);
    if (selection->chosen.empty()) return 0.0;
    return matched / static_cast<double>(selection->chosen.size()) * static_cast<double>(selection->screened_matches) /
           static_cast<double>(selection->screened);
  }
};

/// Deskew inside the registration: the features were deskewed (eq 4.12) with
/// `used`, the previous frame's velocity; after each iteration they are
/// deskewed again with the velocity from the previous centroid pose to the
/// current estimate over dt, so the registration ends with the motion it
/// measured (handheld acceleration otherwise biases the map a frame at a time).
struct MotionDeskew {
  std::span<const float> edge_times;   ///< per edge feature, s from the centroid
  std::span<const float> plane_times;  ///< per plane feature
  SE3 T_world_previous;                ///< the previous frame's centroid pose
  double dt = 0.0;                     ///< centroid to centroid, s (> 0)
  BodyVelocity used;                   ///< the velocity the features were deskewed with
};

/// Eq 4.23's Sigma_p of each query in the base frame (point_uncertainty.hpp): each plane row is weighted by
/// uncertainty_weight on top of its Huber weight (also in the hessian and the selection's information).
struct QueryCovariances {
  std::span<const PointCovariance> edges;   ///< one per edge feature
  std::span<const PointCovariance> planes;  ///< one per plane feature
  double residual_sigma_m = 0.05;           ///< sigma_0
};

/// max_correspondence_m bounds the residual of a correspondence (and is the least search radius).
/// With `motion`, the features are deskewed again between iterations and
/// `velocity_used` of the result holds the velocity of the last deskew.
/// With `covariances`, the rows are weighted by the queries' uncertainty (eq 4.23).
RegistrationResult register_scan_to_map(std::span<const Eigen::Vector3f> edges_base, std::span<const Eigen::Vector3f> planes_base,
                                        const VoxelMap& edge_map, const VoxelMap& plane_map, const SE3& initial,
                                        double max_correspondence_m, const RegistrationConfig& config, const MotionDeskew* motion = nullptr,
                                        const QueryCovariances* covariances = nullptr);

/// The degeneracy factors (thesis sec 5.4.4, feature_selection.hpp) of the
/// information of every feature that has a correspondence at `pose`; one
/// search per feature.
Degeneracy full_set_degeneracy(std::span<const Eigen::Vector3f> edges, std::span<const Eigen::Vector3f> planes, const VoxelMap& edge_map,
                               const VoxelMap& plane_map, const SE3& pose, double max_correspondence_m, const RegistrationConfig& config);

}  // namespace mlidar::slam
