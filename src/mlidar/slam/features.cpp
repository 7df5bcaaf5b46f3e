#include "mlidar/slam/features.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mlidar::slam {
namespace {

constexpr int kHalfWindow = 5;

/// Marks occluded and grazing points (LOAM sec V-A) as blocked.
void block_unreliable(std::span<const float> ranges, const FeatureConfig& config, std::span<std::uint8_t> blocked) {
  const int n = static_cast<int>(ranges.size());
  for (int i = kHalfWindow; i + kHalfWindow + 1 < n; ++i) {
    const float near = ranges[static_cast<std::size_t>(i)];
    const float next = ranges[static_cast<std::size_t>(i + 1)];
    if (next - near > config.occlusion_jump_m) {
      for (int k = 1; k <= kHalfWindow + 1; ++k) blocked[static_cast<std::size_t>(i + k)] = 1;
    } else if (near - next > config.occlusion_jump_m) {
      for (int k = 0; k <= kHalfWindow; ++k) blocked[static_cast<std::size_t>(i - k)] = 1;
    }
  }
  for (int i = 1; i + 1 < n; ++i) {
    const float r = ranges[static_cast<std::size_t>(i)];
    const float limit = static_cast<float>(config.grazing_ratio) * r;
    if (std::abs(ranges[static_cast<std::size_t>(i - 1)] - r) > limit && std::abs(ranges[static_cast<std::size_t>(i + 1)] - r) > limit)
      blocked[static_cast<std::size_t>(i)] = 1;
  }
}

void block_neighbours(int i, int n, std::span<std::uint8_t> blocked) {
  for (int k = std::max(0, i - kHalfWindow); k <= std::min(n - 1, i + kHalfWindow); ++k) blocked[static_cast<std::size_t>(k)] = 1;
}

/// Calls visit(i) on `candidates` in `before` order until it returns true or
/// they run out. Sorts lazily: a chunk (starting at 2 * wanted, doubling) is
/// selected with nth_element and sorted only when the walk reaches it, since
/// most picks end within the first few (a full sort per sector was 8 % of slam).
template <typename Before, typename Visit>
void walk_in_order(std::vector<std::uint32_t>& candidates, int wanted, Before before, Visit visit) {
  if (wanted <= 0) return;
  auto first = candidates.begin();
  auto chunk = static_cast<std::ptrdiff_t>(2 * wanted);
  while (first != candidates.end()) {
    const auto last = candidates.end() - first > chunk ? first + chunk : candidates.end();
    if (last != candidates.end()) std::nth_element(first, last, candidates.end(), before);
    std::sort(first, last, before);
    for (; first != last; ++first)
      if (visit(*first)) return;
    chunk *= 2;
  }
}

}  // namespace

void row_curvature(std::span<const float> ranges, std::span<float> curvature) {
  const int n = static_cast<int>(ranges.size());
  for (int i = 0; i < n; ++i) {
    if (i < kHalfWindow || i + kHalfWindow >= n) {
      curvature[static_cast<std::size_t>(i)] = std::numeric_limits<float>::infinity();
      continue;
    }
    float sum = 0.0F;
    for (int j = i - kHalfWindow; j <= i + kHalfWindow; ++j) sum += ranges[static_cast<std::size_t>(j)];
    const float r = ranges[static_cast<std::size_t>(i)];
    sum -= static_cast<float>(2 * kHalfWindow + 1) * r;
    curvature[static_cast<std::size_t>(i)] = std::abs(sum) / (static_cast<float>(2 * kHalfWindow) * r);
  }
}

void extract_features(const RangeImage& image, const Segmentation& segmentation, const FeatureConfig& config, FeatureWorkspace& ws,
                      FeatureIndices& out) {
  out.edges.clear();
  out.planes.clear();
  std::vector<float>& ranges = ws.curvature;  // reused: ranges first, then kept separately below
  for (int row = 0; row < image.rows; ++row) {
    ws.pixel.clear();
    for (int col = 0; col < image.cols; ++col) {
      const std::size_t p = image.pixel(row, col);
      if (segmentation.kept(p)) ws.pixel.push_back(static_cast<std::uint32_t>(p));
    }
    const int n = static_cast<int>(ws.pixel.size());
    if (n < 2 * kHalfWindow + 1) continue;
    ranges.resize(static_cast<std::size_t>(n) * 2);
    std::span<float> row_ranges(ranges.data(), static_cast<std::size_t>(n));
    std::span<float> curvature(ranges.data() + n, static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) row_ranges[static_cast<std::size_t>(i)] = image.range[ws.pixel[static_cast<std::size_t>(i)]];
    row_curvature(row_ranges, curvature);
    ws.blocked.assign(static_cast<std::size_t>(n), 0);
    block_unreliable(row_ranges, config, ws.blocked);

    for (int s = 0; s < config.sectors; ++s) {
      const int begin = kHalfWindow + (n - 2 * kHalfWindow) * s / config.sectors;
      const int end = kHalfWindow + (n - 2 * kHalfWindow) * (s + 1) / config.sectors;
      if (end <= begin) continue;
      // Edges: candidates above edge_threshold, highest curvature first.
      ws.order.clear();
      for (int i = begin; i < end; ++i)
        if (curvature[static_cast<std::size_t>(i)] > config.edge_threshold) ws.order.push_back(static_cast<std::uint32_t>(i));
      int edges = 0;
      walk_in_order(
          ws.order, config.edges_per_sector, [&](std::uint32_t a, std::uint32_t b) { return curvature[a] > curvature[b]; },
          [&](std::uint32_t i) {
            const std::size_t pixel = ws.pixel[i];
            if (ws.blocked[i] != 0 || segmentation.label[pixel] == Segmentation::kGround) return false;
            out.edges.push_back(static_cast<std::uint32_t>(image.index[pixel]));
            block_neighbours(static_cast<int>(i), n, ws.blocked);
            return ++edges >= config.edges_per_sector;
          });
      // Planes: candidates below plane_threshold, lowest curvature first.
      ws.order.clear();
      for (int i = begin; i < end; ++i)
        if (curvature[static_cast<std::size_t>(i)] < config.plane_threshold) ws.order.push_back(static_cast<std::uint32_t>(i));
      int planes = 0;
      walk_in_order(
          ws.order, config.planes_per_sector, [&](std::uint32_t a, std::uint32_t b) { return curvature[a] < curvature[b]; },
          [&](std::uint32_t i) {
            if (ws.blocked[i] != 0) return false;
            out.planes.push_back(static_cast<std::uint32_t>(image.index[ws.pixel[i]]));
            block_neighbours(static_cast<int>(i), n, ws.blocked);
            return ++planes >= config.planes_per_sector;
          });
    }
  }
}

}  // namespace mlidar::slam
