#pragma once
// Map sharpness without ground truth: mean map entropy (MME) and mean plane
// variance (MPV), Razlaw et al., "Evaluation of registration methods for
// sparse 3D laser scans", ECMR 2015; thesis eq 4.32.
//   H(p)  = 1/2 ln |2 pi e Sigma(p)|   (differential entropy of a Gaussian)
//   MME   = mean of H(p) over the points whose neighbourhood gives a full-rank Sigma
//   MPV   = mean of the smallest eigenvalue of Sigma(p) (variance across the local plane)
// Sigma(p) is the sample covariance (1/(n-1)) of the points within `radius` of p, p included.
// Note: thesis eq 4.32 prints ln|2 pi e C| without the 1/2; its values are 2 x MME here.
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace mlidar::eval {

struct MapMetricsOptions {
  double radius = 0.3;            ///< neighbourhood radius, metres (> 0)
  std::size_t min_neighbors = 5;  ///< points with fewer neighbours (self included) are skipped (>= 4)
};

/// tr(Sigma) of the points' covariances (map.ply's cov_ fields, m^2): the thesis's magnitude of a covariance (sec 4.8.1).
struct CovarianceTraceStats {
  std::size_t count = 0;
  double mean = 0.0, p50 = 0.0, p95 = 0.0, max = 0.0;  ///< NaN when count == 0
};
/// `traces` in any order; percentiles by the nearest rank.
CovarianceTraceStats summarize_traces(std::vector<double> traces);

struct MapMetrics {
  std::size_t points = 0;                                ///< points given
  std::size_t points_used = 0;                           ///< points with enough neighbours and a full-rank covariance
  double mean_map_entropy = 0.0;                         ///< NaN when points_used == 0
  double mean_plane_variance = 0.0;                      ///< m^2; NaN when points_used == 0
  std::optional<CovarianceTraceStats> covariance_trace;  ///< when the map has per-point covariances
};

/// O(N k log N) with a k-d tree. Non-finite points are ignored. Throws
/// std::invalid_argument for radius <= 0 or min_neighbors < 4 (callers check options).
MapMetrics compute_map_metrics(const std::vector<Eigen::Vector3f>& points, const MapMetricsOptions& options = {});

}  // namespace mlidar::eval
