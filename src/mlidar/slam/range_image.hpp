#pragma once
// Range image of one spinning-LiDAR sweep (thesis sec 4.5.1): row = beam
// (ring), column = azimuth bin, pixel = range of the point that fell there.
// Rows come from the `ring` channel when present; otherwise from the point's
// elevation matched to the nearest angle of the model's table (binary search
// over the sorted table, so unevenly spaced real tables work).
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/types.hpp"

namespace mlidar::slam {

/// Row-major rows x cols image; index == kEmpty marks a pixel without a point.
struct RangeImage {
  static constexpr std::int32_t kEmpty = -1;
  int rows = 0;
  int cols = 0;
  std::vector<float> range;         ///< metres, 0 where empty
  std::vector<std::int32_t> index;  ///< point index into the scan, or kEmpty

  std::size_t pixel(int row, int col) const {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(col);
  }
};

/// Row of the table angle nearest to elevation_deg; table sorted ascending, non-empty.
int nearest_row(std::span<const double> sorted_angles_deg, double elevation_deg);

/// atan2(y, x) in (-pi, pi] from Abramowitz & Stegun 4.4.49 (odd polynomial
/// of degree 17 on [0, 1], |error| <= 2e-8 rad; octant reduction), about 4x
/// cheaper than std::atan2. atan2(0, 0) = 0.
double fast_atan2(double y, double x);

/// Projects `points` (LiDAR frame) into a rows x cols image with
/// rows = model.rings() and cols = round(360 / horizontal_resolution_deg).
/// `ring` is empty or one entry per point; ring values >= rows, non-finite
/// points and ranges outside [min_range, max_range] are skipped. When two
/// points share a pixel the nearer one is kept. `image` is reused (no
/// allocation once its buffers are large enough).
/// Throws std::invalid_argument for a model without angles or sizes that differ.
void build_range_image(std::span<const Eigen::Vector3f> points, std::span<const std::uint16_t> ring, const LidarModel& model,
                       RangeImage& image);

}  // namespace mlidar::slam
