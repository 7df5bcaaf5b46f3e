#pragma once
// Scan rows of a spinning-LiDAR cloud that carries no `ring` channel (keyframe
// folders, exported maps: BALM's Ouster keyframes). A beam keeps its elevation
// over a sweep, so the elevation histogram has one narrow peak per beam, but
// three things blur it on real clouds:
//   - the beams start above the frame's origin (Ouster: ~3.6 cm), so near
//     points sit higher than far ones: elevations are taken from a height
//     z0 above the origin, the z0 of a small grid that gives the sharpest
//     histogram;
//   - a deskewed sweep is expressed at one instant, so a tilt of the sensor
//     during the sweep moves every beam's elevation by an amount that drifts
//     with azimuth: the cloud is cut into azimuth sectors and each sector's
//     histogram is shifted onto its neighbour's (cross-correlation within a
//     fraction of the beam spacing), the shifts accumulated around the sweep;
//   - points between beams (noise, mixed pixels).
// Rows are then the peaks of the corrected histogram, split at its valleys
// (peaks with a shallow valley between them merged), numbered by ascending
// elevation, each point given the row whose interval holds it.
// The cloud is judged to have rows only when the peaks are narrow against
// their spacing (a solid-state scanner's rosette, a random cloud or sweeps
// merged from several poses have no such structure); otherwise no rows come
// back and the caller keeps its fallback.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/core/types.hpp"

namespace mlidar::slam {

struct RowRecoveryConfig {
  double bin_deg = 0.05;           ///< elevation histogram bin
  double sector_deg = 5.0;         ///< azimuth sector whose shift is estimated
  double max_step_deg = 0.3;       ///< largest shift between adjacent sectors
  double origin_z_range_m = 0.06;  ///< z0 searched in [-range, +range]
  double origin_z_step_m = 0.01;
  int min_rows = 8;                 ///< fewer: not a multi-beam spinning scan
  double min_assigned_share = 0.8;  ///< of the usable points, inside a row
  /// Median over rows of (std of its corrected elevations) / (spacing to its
  /// nearest neighbour row) at most this: a uniform spread gives ~0.29. BALM's
  /// still keyframes 20-25: 0.025-0.030 with exactly the sensor's 64 rows;
  /// keyframes merged from sweeps taken while moving: 0.075 (frame 22, 128
  /// peaks: two sweeps) to 0.22 with 108-138 peaks interleaving the sweeps'
  /// beams, whose range images made BALM pairs 0.5 m off
  /// (docs/benchmarks.md "Ring-less clouds").
  double max_width_ratio = 0.06;
  double merge_valley_ratio = 0.5;  ///< peaks whose valley exceeds this x the lower peak are one row
  double min_range_m = 0.5;         ///< nearer points are ignored (and get no row)
};

inline constexpr std::uint16_t kNoRow = 0xFFFF;

struct RecoveredRows {
  /// One entry per input point: its row (0 = lowest elevation), or kNoRow.
  std::vector<std::uint16_t> ring;
  /// vertical_angles_deg: each row's median corrected elevation, ascending;
  /// horizontal_resolution_deg: the median azimuth step within rows.
  LidarModel model;
  double origin_z_m = 0.0;      ///< the beams' height above the origin that sharpened the histogram most
  double assigned_share = 0.0;  ///< of the usable points
  double width_ratio = 0.0;     ///< as RowRecoveryConfig::max_width_ratio
};

/// Rows of a scan that has a `ring` channel but no model (a folder of clouds):
/// each ring's median elevation, rings renumbered by ascending elevation (the
/// range image's row order), the median azimuth step within rings; none when
/// fewer than min_rows rings hold 16 points or more. origin_z_m is 0 and every
/// point of such a ring is assigned.
std::optional<RecoveredRows> rows_from_ring_channel(std::span<const Eigen::Vector3f> points, std::span<const std::uint16_t> ring,
                                                    const RowRecoveryConfig& config = {});

/// Rows of `points` (LiDAR frame); none when the cloud shows no row structure.
std::optional<RecoveredRows> recover_rows(std::span<const Eigen::Vector3f> points, const RowRecoveryConfig& config = {});

}  // namespace mlidar::slam
