#pragma once
// Appearance-only refinement of one LiDAR pair from single scans (issue 8,
// thesis 3.4.3): robust point-to-plane ICP of the target scan against the
// reference scan from the guess; when that registration is poor (or when
// asked) a multi-start search from ground-plane-aligned starts with a yaw
// sweep (coarse_search.hpp) looks for a better basin; the answer is then
// averaged with the reverse registration (reference onto target). The verdict says
// whether the answer can be trusted and whether it took a search; the reasons
// say why not. Never a silently wrong answer: a result that fails a check is
// reported as not converged.
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "mlidar/calib/coarse_search.hpp"
#include "mlidar/calib/point_to_plane_icp.hpp"
#include "mlidar/calib/ref_surface.hpp"

namespace mlidar::calib {

enum class PairSearchMode { kAuto, kAlways, kNever };
enum class PairVerdict { kConverged, kSearchedAndConverged, kNotConverged };
std::string_view to_string(PairVerdict verdict);  ///< "converged", "searched_and_converged", "not_converged"
/// Whether a result with this verdict may be used: it passed every check (with or without the search).
inline bool is_trusted(PairVerdict verdict) { return verdict != PairVerdict::kNotConverged; }

struct PairRefineConfig {
  double min_range = 2.0;        ///< m, nearer points (the vehicle's own body) are dropped from both scans
  double ref_voxel_size = 0.05;  ///< m, the reference cloud is thinned to this before the k-d tree
  SurfaceConfig surface;
  IcpConfig icp;  ///< from the guess and for the final candidates
  IcpConfig search_icp{.levels = {{1.0, 2.0, 0.5}}, .max_iterations = 8, .max_points = 500};  ///< short ICP per start
  CoarseSearchConfig search;
  double search_ref_voxel_size = 0.25;  ///< m, the short ICPs of the search use a reference thinned to this
  PairSearchMode search_mode = PairSearchMode::kAuto;
  std::size_t search_finalists = 2;  ///< best distinct starts refined with the full ICP
  double overlap_radius = 0.3;       ///< m, r of eq 3.13
  double fitness_voxel_size = 0.5;   ///< m, target thinning for the overlap fitness
  // Checks a result must pass to be trusted:
  double min_overlap = 0.3;            ///< fraction of target points near the reference (|S^b| / |P^b|)
  double max_rmse = 0.1;               ///< m, point-to-plane rmse of the final level's inliers
  double max_rotation_sd_deg = 0.5;    ///< largest 1-sigma rotation of the covariance
  double max_translation_sd_m = 0.05;  ///< largest 1-sigma translation of the covariance
  double ambiguity_margin = 0.03;      ///< a different pose this close in overlap makes the answer ambiguous
  double distinct_rotation_deg = 2.0;  ///< poses farther apart than this (or distinct_translation_m) are different
  double distinct_translation_m = 0.2;
  /// Also register the reference to the target from the answer and return the
  /// midpoint of the two (each direction's point-to-plane bias, from whose
  /// normals are used, enters with opposite sign); skipped when that reverse
  /// registration does not settle or lands a distinct pose away.
  bool symmetric = true;
  // Per-scene systematic error added to the reported covariance (1-sigma per axis): what one
  // pair of single scans cannot see from its own residuals (capture-time offsets between the
  // LiDARs, motion during the sweep, surface sampling). Default: the pooled per-axis scatter of
  // the three opencalib_3lidar scenes, left and right (docs/benchmarks.md, "Pairwise refinement").
  double systematic_rotation_sd_deg = 0.09;
  double systematic_translation_sd_m = 0.01;
};

/// One start of the search, after its short ICP.
struct SearchStart {
  std::string label;
  SE3 T_start;
  SE3 T_after;
  double overlap = 0.0;  ///< |S^b| / |P^b| at T_after
  double rmse = 0.0;
};

struct PairRefineResult {
  PairVerdict verdict = PairVerdict::kNotConverged;
  std::vector<std::string> reasons;  ///< why not converged; empty when trusted
  SE3 T_init;
  SE3 T_ref_target;
  Mat6 information = Mat6::Zero();     ///< J^T W J of the final ICP, left perturbation [rho, phi]
  Mat6 covariance = Mat6::Zero();      ///< [t, r]: t additive, r as a left perturbation Exp(d) R; covariance_icp + systematic term
  Mat6 covariance_icp = Mat6::Zero();  ///< same frame, the ICP's s^2 H^-1 alone (points independent: over-confident)
  double rotation_sd_deg = 0.0;        ///< sqrt of the largest eigenvalue of the rotation block
  double translation_sd_m = 0.0;       ///< same for the translation block
  double rmse = 0.0;                   ///< m
  double inlier_ratio = 0.0;           ///< matched / thinned target points, final level
  Overlap overlap;                     ///< eq 3.13-3.14 at the answer, radius overlap_radius
  int iterations = 0;
  bool searched = false;              ///< the multi-start search ran
  bool symmetric = false;             ///< the answer is the midpoint of both directions (PairRefineConfig::symmetric)
  std::string chosen_start = "init";  ///< "init" or the label of the winning start
  std::vector<SearchStart> starts;    ///< every start tried, in order
};

/// ref and target are single scans in their own frames; T_init maps target
/// points into the reference frame (p_ref = T p_target). Non-finite points are
/// ignored. Throws std::invalid_argument for a config out of range.
PairRefineResult refine_pair(std::span<const Eigen::Vector3f> ref, std::span<const Eigen::Vector3f> target, const SE3& T_init,
                             const PairRefineConfig& config = {});

}  // namespace mlidar::calib
