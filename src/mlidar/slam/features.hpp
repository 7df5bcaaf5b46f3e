#pragma once
// LOAM feature extraction (Zhang & Singh 2014; thesis sec 4.5.2) on a
// segmented range image. Per row, over the kept pixels in azimuth order:
//   curvature c_i = |sum_{j = i-5..i+5, j != i} (r_j - r_i)| / (10 r_i)
// (range-normalised, so one threshold serves all distances). Points are
// rejected when they are occluded (a depth jump > occlusion_jump_m to a
// neighbour: the farther side's neighbours go) or grazing (both neighbours'
// range differences exceed grazing_ratio * r_i). Each row is cut into
// `sectors` so features spread over the sweep; per sector the highest-c
// non-ground points above edge_threshold become edges and the lowest-c
// points below plane_threshold become planes, each pick blocking its
// +-5 neighbours.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/slam/range_image.hpp"
#include "mlidar/slam/segmentation.hpp"

namespace mlidar::slam {

struct FeatureConfig {
  int sectors = 6;
  int edges_per_sector = 4;
  int planes_per_sector = 20;
  double edge_threshold = 0.005;
  double plane_threshold = 0.002;
  double occlusion_jump_m = 0.3;
  double grazing_ratio = 0.02;
};

/// Indices into the scan's points.
struct FeatureIndices {
  std::vector<std::uint32_t> edges;
  std::vector<std::uint32_t> planes;
};

/// Reusable per-row buffers so repeated calls do not allocate.
struct FeatureWorkspace {
  std::vector<std::uint32_t> pixel;  ///< kept pixels of the current row
  std::vector<float> curvature;
  std::vector<std::uint8_t> blocked;
  std::vector<std::uint64_t> edge_candidates;  ///< of the current sector: sort keys (curvature, position)
  std::vector<std::uint64_t> plane_candidates;
};

/// Curvature of kept pixels of one row (ranges in azimuth order) into `curvature`;
/// the first and last 5 entries get +infinity (no full neighbourhood).
void row_curvature(std::span<const float> ranges, std::span<float> curvature);

/// Rearranges `keys` so that the first `count` are the `count` smallest (in no particular order), as
/// std::nth_element does: quickselect with a median-of-three pivot and a partition without branches (the
/// comparisons of noisy curvatures defeat branch prediction; std::nth_element was half of extract_features).
void select_smallest(std::span<std::uint64_t> keys, std::size_t count);

void extract_features(const RangeImage& image, const Segmentation& segmentation, const FeatureConfig& config, FeatureWorkspace& workspace,
                      FeatureIndices& out);

}  // namespace mlidar::slam
