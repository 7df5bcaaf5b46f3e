#pragma once
// A map against the scene's true surfaces (io/surface_samples.hpp): each map
// point's signed distance along the normal of its nearest surface sample, and,
// when the map carries point covariances, that distance normalized by the
// covariance along the same normal, e = n^T (p - q) / sqrt(n^T Sigma n). For
// honest covariances e is about N(0, 1): variance near 1 and 95 % of the
// points with |e| <= 1.96.
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mlidar/eval/statistics.hpp"
#include "mlidar/io/point_covariance_fields.hpp"
#include "mlidar/io/surface_samples.hpp"

namespace mlidar::eval {

struct SurfaceErrorOptions {
  double max_distance_m = 0.5;  ///< a map point farther than this from every sample is not matched (moving objects, outliers)
};

struct NormalizedSurfaceError {
  std::size_t count = 0;
  double mean = 0.0, variance = 0.0;  ///< variance about zero: the mean of e^2
  double inside_95 = 0.0;             ///< share with |e| <= 1.96
};

struct SurfaceError {
  std::size_t points = 0;      ///< map points given
  std::size_t matched = 0;     ///< within max_distance_m of a sample
  ErrorStats distance_m;       ///< |n^T (p - q)| of the matched points
  double signed_mean_m = 0.0;  ///< mean of n^T (p - q), n facing the sensor that saw the sample: < 0 behind the surface
  std::optional<NormalizedSurfaceError> normalized;  ///< when covariances are given
};

/// `covariances`, when given, one per point. std::invalid_argument for a size mismatch, no samples or
/// max_distance_m <= 0.
SurfaceError surface_error(const std::vector<Eigen::Vector3f>& points, const std::optional<std::vector<io::UpperCovariance>>& covariances,
                           const io::SurfaceSamples& surfaces, const SurfaceErrorOptions& options = {});

}  // namespace mlidar::eval
