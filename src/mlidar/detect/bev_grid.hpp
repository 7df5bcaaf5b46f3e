#pragma once
// Stage 1's input (thesis 6.5.1; SECOND V1.5's feature learning simplified to the mean of the points in a voxel):
// points of the base frame gathered into vertical pillars on a bird's-eye-view grid, each pillar's features the
// mean of its points and a few shape statistics, as a dense channels x rows x cols array for a 2D CNN (sparse
// convolution is not packaged; a dense BEV network is the realistic equivalent on CPU).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::detect {

struct BevGridConfig {
  double x_min = -48.0, x_max = 48.0;  ///< metres in the base frame; columns run along x
  double y_min = -48.0, y_max = 48.0;  ///< rows run along y
  double z_min = -3.0, z_max = 3.0;    ///< points outside are left out
  double cell = 0.4;                   ///< pillar side, metres
};

/// The channels of a pillar, in this order.
enum BevChannel : int {
  kMeanX,          ///< mean x of the pillar's points minus the pillar centre's x (m)
  kMeanY,          ///< likewise y
  kMeanZ,          ///< mean z (m)
  kMaxZ,           ///< highest z (m)
  kMinZ,           ///< lowest z (m)
  kMeanIntensity,  ///< mean intensity (0 when none is given)
  kMeanUncertainty,  ///< mean tr(Ξ) of the points (eq 6.7, m²; 0 when none is given)
  kLogCount,       ///< log(1 + number of points)
  kBevChannels
};

struct BevGrid {
  int rows = 0;
  int cols = 0;
  std::vector<float> features;  ///< kBevChannels x rows x cols, row-major; empty pillars are all zero
  std::vector<std::uint32_t> counts;  ///< points per pillar, rows x cols

  float at(int channel, int row, int col) const { return features[(static_cast<std::size_t>(channel) * rows + row) * cols + col]; }
  /// The cell holding (x, y), or nullopt outside the grid.
  static std::optional<std::pair<int, int>> cell_of(double x, double y, const BevGridConfig& config);
};

/// The grid of `points` (base frame) with their `intensity` and `uncertainty` (one per point, or empty).
BevGrid make_bev_grid(std::span<const Vec3> points, std::span<const float> intensity, std::span<const double> uncertainty,
                      const BevGridConfig& config);

}  // namespace mlidar::detect
