#include "mlidar/slam/row_recovery.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "mlidar/core/median.hpp"
#include "mlidar/slam/range_image.hpp"

namespace mlidar::slam {
namespace {

constexpr double kDegrees = 180.0 / std::numbers::pi;

/// Azimuth of p in [0, 360) deg.
double azimuth_deg(const Eigen::Vector3f& p) {
  const double azimuth = fast_atan2(p.y(), p.x()) * kDegrees;
  return azimuth < 0.0 ? azimuth + 360.0 : azimuth;
}

/// The points rows are recovered from: finite, beyond the minimum range.
struct UsablePoints {
  std::vector<std::uint32_t> index;  ///< into the input
  std::vector<float> rho, z;         ///< horizontal distance and height
  std::vector<float> azimuth_deg;    ///< in [0, 360)
  std::vector<std::uint16_t> sector;
};

UsablePoints usable_points(std::span<const Eigen::Vector3f> points, const RowRecoveryConfig& config) {
  UsablePoints usable;
  const int sectors = std::max(1, static_cast<int>(std::lround(360.0 / config.sector_deg)));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite() || p.norm() < config.min_range_m) continue;
    const double azimuth = azimuth_deg(p);
    usable.index.push_back(static_cast<std::uint32_t>(i));
    usable.rho.push_back(std::hypot(p.x(), p.y()));
    usable.z.push_back(p.z());
    usable.azimuth_deg.push_back(static_cast<float>(azimuth));
    usable.sector.push_back(static_cast<std::uint16_t>(std::min(sectors - 1, static_cast<int>(azimuth / 360.0 * sectors))));
  }
  return usable;
}

/// Elevation histograms over [-90, 90] deg.
class Histograms {
 public:
  Histograms(double bin_deg, int sectors) : bin_deg_(bin_deg), bins_(static_cast<int>(std::ceil(180.0 / bin_deg)) + 1), sectors_(sectors) {}
  int bins() const { return bins_; }
  int bin(double elevation_deg) const { return std::clamp(static_cast<int>(std::floor((elevation_deg + 90.0) / bin_deg_)), 0, bins_ - 1); }
  double centre_deg(double bin) const { return (bin + 0.5) * bin_deg_ - 90.0; }
  int sectors() const { return sectors_; }

 private:
  double bin_deg_;
  int bins_;
  int sectors_;
};

/// Two passes of [1 2 1] / 4.
std::vector<double> smoothed(std::vector<double> counts) {
  std::vector<double> next(counts.size(), 0.0);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t j = 0; j < counts.size(); ++j) {
      const double left = j > 0 ? counts[j - 1] : 0.0;
      const double right = j + 1 < counts.size() ? counts[j + 1] : 0.0;
      next[j] = 0.25 * left + 0.5 * counts[j] + 0.25 * right;
    }
    counts.swap(next);
  }
  return counts;
}

/// One sector's smoothed elevation histogram, held only over [first, first + counts.size()):
/// the bins of its points and two beyond on each side (the two smoothing passes spread that far).
struct SectorHistogram {
  int first = 0;
  std::vector<double> counts;
  bool empty() const { return counts.empty(); }
  int last() const { return first + static_cast<int>(counts.size()) - 1; }
  double at(int bin) const { return counts[static_cast<std::size_t>(bin - first)]; }
};

/// Every sector's histogram: the bins of its points counted, then smoothed as `smoothed` does
/// (outside the held range every bin is zero, so the values are the same).
std::vector<SectorHistogram> sector_histograms(const std::vector<int>& bins, const UsablePoints& usable, const Histograms& h) {
  const auto sectors = static_cast<std::size_t>(h.sectors());
  std::vector<int> lo(sectors, h.bins()), hi(sectors, -1);
  for (std::size_t k = 0; k < bins.size(); ++k) {
    lo[usable.sector[k]] = std::min(lo[usable.sector[k]], bins[k]);
    hi[usable.sector[k]] = std::max(hi[usable.sector[k]], bins[k]);
  }
  std::vector<SectorHistogram> histogram(sectors);
  for (std::size_t s = 0; s < sectors; ++s) {
    if (hi[s] < 0) continue;
    histogram[s].first = std::max(0, lo[s] - 2);
    histogram[s].counts.assign(static_cast<std::size_t>(std::min(h.bins() - 1, hi[s] + 2) - histogram[s].first + 1), 0.0);
  }
  for (std::size_t k = 0; k < bins.size(); ++k) {
    SectorHistogram& sector = histogram[usable.sector[k]];
    sector.counts[static_cast<std::size_t>(bins[k] - sector.first)] += 1.0;
  }
  for (SectorHistogram& sector : histogram)
    if (!sector.empty()) sector.counts = smoothed(std::move(sector.counts));
  return histogram;
}

/// Sum over the sector's bins a of histogram(a) x templ(a - shift). Every value is a
/// multiple of 1/16 (counts smoothed by [1 4 6 4 1] / 16, and sums of those), so each
/// product and every partial sum is exact in a double (far below 2^45 x 1/256 here):
/// four running sums give the same score as one, without one long chain of additions.
double correlation(const SectorHistogram& sector, const std::vector<double>& templ, int shift) {
  const int begin = std::max(sector.first, shift), end = std::min(sector.last(), static_cast<int>(templ.size()) - 1 + shift) + 1;
  std::array<double, 4> sums{};
  int a = begin;
  for (; a + 4 <= end; a += 4)
    for (int lane = 0; lane < 4; ++lane)
      sums[static_cast<std::size_t>(lane)] += sector.at(a + lane) * templ[static_cast<std::size_t>(a + lane - shift)];
  for (; a < end; ++a) sums[0] += sector.at(a) * templ[static_cast<std::size_t>(a - shift)];
  return (sums[0] + sums[1]) + (sums[2] + sums[3]);
}

/// Per sector, the bin shift that maps its beams onto those of the sectors
/// before it: each sector's smoothed histogram cross-correlated with the sum
/// of the last few sectors' corrected ones (a template, so steps smaller than
/// a bin do not round away as they would between neighbours), within
/// +-max_step bins of the previous sector's shift; re-centred on zero.
std::vector<int> sector_shifts(const std::vector<int>& bins, const UsablePoints& usable, const Histograms& h, int max_step) {
  constexpr std::size_t kTemplateSectors = 6;
  const auto sectors = static_cast<std::size_t>(h.sectors());
  const std::vector<SectorHistogram> histogram = sector_histograms(bins, usable, h);
  // The template: the last kTemplateSectors non-empty sectors' histograms, in corrected bins.
  std::vector<double> templ(static_cast<std::size_t>(h.bins()), 0.0);
  const auto add_to_template = [&](std::size_t sector, double sign, int offset) {
    for (int bin = histogram[sector].first; bin <= histogram[sector].last(); ++bin) {
      const int corrected = bin - offset;
      if (corrected >= 0 && corrected < h.bins()) templ[static_cast<std::size_t>(corrected)] += sign * histogram[sector].at(bin);
    }
  };
  std::vector<int> shift(sectors, 0);
  std::vector<std::size_t> matched;  // non-empty sectors so far
  int current = 0;
  for (std::size_t s = 0; s < sectors; ++s) {
    if (!histogram[s].empty() && !matched.empty()) {
      double best = -1.0;
      int best_shift = current;
      for (int candidate = current - max_step; candidate <= current + max_step; ++candidate) {
        const double score = correlation(histogram[s], templ, candidate);
        // Ties go to the smaller step.
        if (score > best + 1e-9 || (std::abs(score - best) <= 1e-9 && std::abs(candidate - current) < std::abs(best_shift - current))) {
          best = score;
          best_shift = candidate;
        }
      }
      current = best_shift;
    }
    shift[s] = current;
    if (histogram[s].empty()) continue;
    matched.push_back(s);
    add_to_template(s, 1.0, current);
    if (matched.size() > kTemplateSectors) {
      const std::size_t leaving = matched[matched.size() - 1 - kTemplateSectors];
      add_to_template(leaving, -1.0, shift[leaving]);
    }
  }
  long sum = 0;
  for (const int value : shift) sum += value;
  const int mean = static_cast<int>(std::lround(static_cast<double>(sum) / static_cast<double>(sectors)));
  for (int& value : shift) value -= mean;
  return shift;
}

std::vector<int> elevation_bins(const UsablePoints& usable, double origin_z, const Histograms& h) {
  std::vector<int> bins(usable.rho.size());
  for (std::size_t k = 0; k < bins.size(); ++k) bins[k] = h.bin(fast_atan2(usable.z[k] - origin_z, usable.rho[k]) * kDegrees);
  return bins;
}

std::vector<double> corrected_counts(const std::vector<int>& bins, const std::vector<int>& shift, const UsablePoints& usable,
                                     const Histograms& h) {
  std::vector<double> counts(static_cast<std::size_t>(h.bins()), 0.0);
  for (std::size_t k = 0; k < bins.size(); ++k)
    counts[static_cast<std::size_t>(std::clamp(bins[k] - shift[usable.sector[k]], 0, h.bins() - 1))] += 1.0;
  return counts;
}

double sharpness(const std::vector<double>& counts) {
  double squares = 0.0, total = 0.0;
  for (const double c : counts) {
    squares += c * c;
    total += c;
  }
  return total > 0.0 ? squares / total : 0.0;
}

/// The beams' height above the origin that makes the corrected histogram
/// sharpest: every second step of the grid, then the two beside the best, on
/// at most kSearchPoints of the points (every stride-th).
double best_origin_z(const UsablePoints& usable, const Histograms& h, int max_step, const RowRecoveryConfig& config) {
  constexpr std::size_t kSearchPoints = 16000;
  const std::size_t stride = std::max<std::size_t>(1, usable.rho.size() / kSearchPoints);
  UsablePoints search;
  for (std::size_t k = 0; k < usable.rho.size(); k += stride) {
    search.rho.push_back(usable.rho[k]);
    search.z.push_back(usable.z[k]);
    search.sector.push_back(usable.sector[k]);
  }
  double best_sharpness = -1.0, origin_z = 0.0;
  const auto try_origin = [&](double z0) {
    const std::vector<int> bins = elevation_bins(search, z0, h);
    const double value = sharpness(corrected_counts(bins, sector_shifts(bins, search, h, max_step), search, h));
    if (value > best_sharpness + 1e-12) {
      best_sharpness = value;
      origin_z = z0;
    }
  };
  const int steps = static_cast<int>(std::lround(config.origin_z_range_m / config.origin_z_step_m));
  for (int step = -steps; step <= steps; step += 2) try_origin(step * config.origin_z_step_m);
  const double coarse = origin_z;
  for (const double side : {-1.0, 1.0})
    if (std::abs(coarse + side * config.origin_z_step_m) <= config.origin_z_range_m + 1e-12)
      try_origin(coarse + side * config.origin_z_step_m);
  return origin_z;
}

/// Peaks of the smoothed histogram, those with a shallow valley between them merged.
std::vector<int> histogram_peaks(const std::vector<double>& s, double merge_valley_ratio) {
  std::vector<int> peaks;
  for (int j = 0; j < static_cast<int>(s.size()); ++j) {
    const auto u = static_cast<std::size_t>(j);
    const double left = j > 0 ? s[u - 1] : 0.0;
    const double right = u + 1 < s.size() ? s[u + 1] : 0.0;
    if (s[u] > 0.0 && s[u] >= left && s[u] > right) peaks.push_back(j);
  }
  const auto valley = [&s](int a, int b) { return *std::min_element(s.begin() + a, s.begin() + b + 1); };
  for (bool merged = true; merged && peaks.size() > 1;) {
    merged = false;
    for (std::size_t k = 0; k + 1 < peaks.size(); ++k) {
      const double low = std::min(s[static_cast<std::size_t>(peaks[k])], s[static_cast<std::size_t>(peaks[k + 1])]);
      if (valley(peaks[k], peaks[k + 1]) > merge_valley_ratio * low) {
        const bool keep_first = s[static_cast<std::size_t>(peaks[k])] >= s[static_cast<std::size_t>(peaks[k + 1])];
        peaks.erase(peaks.begin() + static_cast<std::ptrdiff_t>(keep_first ? k + 1 : k));
        merged = true;
        break;
      }
    }
  }
  return peaks;
}

/// Row intervals [lower[r], lower[r + 1]) in corrected bins: valleys between peaks, half a spacing beyond the outer ones.
std::vector<int> row_bounds(const std::vector<double>& s, const std::vector<int>& peaks) {
  std::vector<int> bounds;
  bounds.push_back(peaks.front() - (peaks[1] - peaks[0]) / 2);
  for (std::size_t k = 0; k + 1 < peaks.size(); ++k)
    bounds.push_back(static_cast<int>(std::min_element(s.begin() + peaks[k], s.begin() + peaks[k + 1] + 1) - s.begin()));
  bounds.push_back(peaks.back() + (peaks.back() - peaks[peaks.size() - 2]) / 2 + 1);
  return bounds;
}

/// Median azimuth step between neighbouring points of a row, over the rows.
double azimuth_resolution_deg(const std::vector<std::vector<float>>& row_azimuths) {
  std::vector<double> steps;
  for (std::vector<float> azimuths : row_azimuths) {
    if (azimuths.size() < 16) continue;
    std::sort(azimuths.begin(), azimuths.end());
    std::vector<double> gaps;
    for (std::size_t k = 1; k < azimuths.size(); ++k)
      if (azimuths[k] - azimuths[k - 1] > 1e-3F) gaps.push_back(azimuths[k] - azimuths[k - 1]);
    if (!gaps.empty()) steps.push_back(median(std::move(gaps)));
  }
  return steps.empty() ? 0.0 : median(std::move(steps));
}

}  // namespace

std::optional<RecoveredRows> recover_rows(std::span<const Eigen::Vector3f> points, const RowRecoveryConfig& config) {
  const UsablePoints usable = usable_points(points, config);
  if (usable.index.size() < static_cast<std::size_t>(16 * config.min_rows)) return std::nullopt;
  const Histograms h(config.bin_deg, std::max(1, static_cast<int>(std::lround(360.0 / config.sector_deg))));
  const int max_step = std::max(1, static_cast<int>(std::lround(config.max_step_deg / config.bin_deg)));

  const double origin_z = best_origin_z(usable, h, max_step, config);
  const std::vector<int> bins = elevation_bins(usable, origin_z, h);
  const std::vector<int> shift = sector_shifts(bins, usable, h, max_step);

  const std::vector<double> s = smoothed(corrected_counts(bins, shift, usable, h));
  const std::vector<int> peaks = histogram_peaks(s, config.merge_valley_ratio);
  if (peaks.size() < static_cast<std::size_t>(std::max(2, config.min_rows))) return std::nullopt;
  const std::vector<int> bounds = row_bounds(s, peaks);
  const std::size_t rows = peaks.size();

  // The row of each corrected bin in [bounds.front(), bounds.back()).
  std::vector<std::size_t> row_of_bin(static_cast<std::size_t>(bounds.back() - bounds.front()));
  for (std::size_t row = 0; row < rows; ++row)
    for (int bin = bounds[row]; bin < bounds[row + 1]; ++bin) row_of_bin[static_cast<std::size_t>(bin - bounds.front())] = row;
  std::vector<int> point_row(usable.index.size(), -1);
  std::vector<std::vector<double>> row_elevations(rows);
  for (std::size_t k = 0; k < point_row.size(); ++k) {
    const int corrected = bins[k] - shift[usable.sector[k]];
    if (corrected < bounds.front() || corrected >= bounds.back()) continue;
    const std::size_t row = row_of_bin[static_cast<std::size_t>(corrected - bounds.front())];
    point_row[k] = static_cast<int>(row);
    row_elevations[row].push_back(h.centre_deg(corrected));
  }

  // Rows holding a tenth of the median row's points or less are noise between beams.
  std::vector<double> sizes;
  for (const auto& e : row_elevations) sizes.push_back(static_cast<double>(e.size()));
  const double min_points = 0.1 * median(sizes);
  std::vector<int> renumber(rows, -1);
  RecoveredRows result;
  std::vector<double> kept_centres, kept_spread;
  for (std::size_t r = 0; r < rows; ++r) {
    if (static_cast<double>(row_elevations[r].size()) <= min_points) continue;
    renumber[r] = static_cast<int>(kept_centres.size());
    const double centre = median(row_elevations[r]);
    double sq = 0.0;
    for (const double e : row_elevations[r]) sq += (e - centre) * (e - centre);
    kept_centres.push_back(centre);
    kept_spread.push_back(std::sqrt(sq / static_cast<double>(row_elevations[r].size())));
  }
  if (kept_centres.size() < static_cast<std::size_t>(config.min_rows)) return std::nullopt;

  std::vector<double> ratios;
  for (std::size_t r = 0; r < kept_centres.size(); ++r) {
    double spacing = std::numeric_limits<double>::infinity();
    if (r > 0) spacing = std::min(spacing, kept_centres[r] - kept_centres[r - 1]);
    if (r + 1 < kept_centres.size()) spacing = std::min(spacing, kept_centres[r + 1] - kept_centres[r]);
    ratios.push_back(kept_spread[r] / std::max(spacing, config.bin_deg));
  }
  result.width_ratio = median(ratios);

  result.ring.assign(points.size(), kNoRow);
  std::vector<std::vector<float>> row_azimuths(kept_centres.size());
  std::size_t assigned = 0;
  for (std::size_t k = 0; k < point_row.size(); ++k) {
    if (point_row[k] < 0 || renumber[static_cast<std::size_t>(point_row[k])] < 0) continue;
    const int row = renumber[static_cast<std::size_t>(point_row[k])];
    result.ring[usable.index[k]] = static_cast<std::uint16_t>(row);
    row_azimuths[static_cast<std::size_t>(row)].push_back(usable.azimuth_deg[k]);
    ++assigned;
  }
  result.assigned_share = static_cast<double>(assigned) / static_cast<double>(usable.index.size());
  result.origin_z_m = origin_z;
  if (result.width_ratio > config.max_width_ratio || result.assigned_share < config.min_assigned_share) return std::nullopt;

  result.model.name = "recovered-" + std::to_string(kept_centres.size());
  result.model.vertical_angles_deg = kept_centres;
  result.model.horizontal_resolution_deg = azimuth_resolution_deg(row_azimuths);
  result.model.min_range = config.min_range_m;
  if (!(result.model.horizontal_resolution_deg > 0.0)) return std::nullopt;
  return result;
}

std::optional<RecoveredRows> rows_from_ring_channel(std::span<const Eigen::Vector3f> points, std::span<const std::uint16_t> ring,
                                                    const RowRecoveryConfig& config) {
  if (ring.size() != points.size()) return std::nullopt;
  std::vector<std::vector<double>> elevations;
  std::vector<std::vector<float>> azimuths;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite() || p.norm() < config.min_range_m || ring[i] == kNoRow) continue;
    if (ring[i] >= elevations.size()) {
      elevations.resize(ring[i] + std::size_t{1});
      azimuths.resize(ring[i] + std::size_t{1});
    }
    elevations[ring[i]].push_back(fast_atan2(p.z(), std::hypot(p.x(), p.y())) * kDegrees);
    azimuths[ring[i]].push_back(static_cast<float>(azimuth_deg(p)));
  }
  std::vector<std::pair<double, std::size_t>> rings;  // (median elevation, ring)
  for (std::size_t r = 0; r < elevations.size(); ++r)
    if (elevations[r].size() >= 16) rings.emplace_back(median(elevations[r]), r);
  if (rings.size() < static_cast<std::size_t>(config.min_rows)) return std::nullopt;
  std::sort(rings.begin(), rings.end());
  std::vector<std::uint16_t> rank(elevations.size(), kNoRow);
  RecoveredRows result;
  std::vector<std::vector<float>> row_azimuths;
  for (std::size_t k = 0; k < rings.size(); ++k) {
    rank[rings[k].second] = static_cast<std::uint16_t>(k);
    result.model.vertical_angles_deg.push_back(rings[k].first);
    row_azimuths.push_back(std::move(azimuths[rings[k].second]));
  }
  result.ring.assign(points.size(), kNoRow);
  std::size_t assigned = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (ring[i] < rank.size() && rank[ring[i]] != kNoRow) {
      result.ring[i] = rank[ring[i]];
      ++assigned;
    }
  result.assigned_share = points.empty() ? 0.0 : static_cast<double>(assigned) / static_cast<double>(points.size());
  result.model.name = "ring-channel-" + std::to_string(rings.size());
  result.model.horizontal_resolution_deg = azimuth_resolution_deg(row_azimuths);
  result.model.min_range = config.min_range_m;
  if (!(result.model.horizontal_resolution_deg > 0.0)) return std::nullopt;
  return result;
}

}  // namespace mlidar::slam
