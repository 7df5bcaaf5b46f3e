#include "mlidar/slam/features.hpp"

#include <algorithm>
#include <bit>
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

/// A candidate's sort key: the bits of its curvature (ordered as the values, curvature being >= 0), complemented
/// when the highest come first, above its position in the row (equal curvatures: the earlier position first).
std::uint64_t candidate_key(float curvature, bool highest_first, std::uint32_t position) {
  std::uint32_t bits = std::bit_cast<std::uint32_t>(curvature);
  if (highest_first) bits = ~bits;
  return (static_cast<std::uint64_t>(bits) << 32U) | position;
}

std::uint32_t position_of(std::uint64_t key) { return static_cast<std::uint32_t>(key & 0xFFFFFFFFU); }

/// Calls visit(position) on `candidates` in key order until it returns true or
/// they run out. Sorts lazily: a chunk (starting at 2 * wanted, doubling) is
/// selected (select_smallest) and sorted only when the walk reaches it, since
/// most picks end within the first few (a full sort per sector was 8 % of slam).
template <typename Visit>
void walk_in_order(std::vector<std::uint64_t>& candidates, int wanted, Visit visit) {
  if (wanted <= 0) return;
  auto first = candidates.begin();
  auto chunk = static_cast<std::ptrdiff_t>(2 * wanted);
  while (first != candidates.end()) {
    const auto last = candidates.end() - first > chunk ? first + chunk : candidates.end();
    select_smallest({first, candidates.end()}, static_cast<std::size_t>(last - first));
    std::sort(first, last);
    for (; first != last; ++first)
      if (visit(position_of(*first))) return;
    chunk *= 2;
  }
}

}  // namespace

void select_smallest(std::span<std::uint64_t> keys, std::size_t count) {
  if (count >= keys.size()) return;
  std::size_t lo = 0, hi = keys.size();  // the `count` smallest are keys[0, lo) and some of keys[lo, hi)
  for (int round = 0; hi - lo > 16; ++round) {
    if (round == 64) {  // not shrinking (many equal keys): the library's selection finishes
      std::nth_element(keys.begin() + static_cast<std::ptrdiff_t>(lo), keys.begin() + static_cast<std::ptrdiff_t>(count),
                       keys.begin() + static_cast<std::ptrdiff_t>(hi));
      return;
    }
    const std::uint64_t a = keys[lo], b = keys[lo + (hi - lo) / 2], c = keys[hi - 1];
    const std::uint64_t pivot = std::max(std::min(a, b), std::min(std::max(a, b), c));  // median of three
    std::size_t below = lo;                                                             // keys[lo, below) < pivot <= keys[below, i)
    for (std::size_t i = lo; i < hi; ++i) {
      const std::uint64_t key = keys[i];
      keys[i] = keys[below];
      keys[below] = key;
      below += static_cast<std::size_t>(key < pivot);
    }
    if (below == count) return;
    if (count < below) {
      hi = below;
    } else {
      lo = below;  // unchanged only when nothing is below the pivot (equal keys): the round limit ends that
    }
  }
  std::sort(keys.begin() + static_cast<std::ptrdiff_t>(lo), keys.begin() + static_cast<std::ptrdiff_t>(hi));
}

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
      // Candidates: edges above edge_threshold (highest curvature first), planes below plane_threshold (lowest
      // first), gathered in one pass without branches (each is written, then kept by advancing the end).
      ws.edge_candidates.resize(static_cast<std::size_t>(end - begin));
      ws.plane_candidates.resize(static_cast<std::size_t>(end - begin));
      std::size_t edge_count = 0, plane_count = 0;
      for (int i = begin; i < end; ++i) {
        const float c = curvature[static_cast<std::size_t>(i)];
        const auto position = static_cast<std::uint32_t>(i);
        ws.edge_candidates[edge_count] = candidate_key(c, true, position);
        edge_count += static_cast<std::size_t>(c > config.edge_threshold);
        ws.plane_candidates[plane_count] = candidate_key(c, false, position);
        plane_count += static_cast<std::size_t>(c < config.plane_threshold);
      }
      ws.edge_candidates.resize(edge_count);
      ws.plane_candidates.resize(plane_count);
      int edges = 0;
      walk_in_order(ws.edge_candidates, config.edges_per_sector, [&](std::uint32_t i) {
        const std::size_t pixel = ws.pixel[i];
        if (ws.blocked[i] != 0 || segmentation.label[pixel] == Segmentation::kGround) return false;
        out.edges.push_back(static_cast<std::uint32_t>(image.index[pixel]));
        block_neighbours(static_cast<int>(i), n, ws.blocked);
        return ++edges >= config.edges_per_sector;
      });
      int planes = 0;
      walk_in_order(ws.plane_candidates, config.planes_per_sector, [&](std::uint32_t i) {
        if (ws.blocked[i] != 0) return false;
        out.planes.push_back(static_cast<std::uint32_t>(image.index[ws.pixel[i]]));
        block_neighbours(static_cast<int>(i), n, ws.blocked);
        return ++planes >= config.planes_per_sector;
      });
    }
  }
}

}  // namespace mlidar::slam
