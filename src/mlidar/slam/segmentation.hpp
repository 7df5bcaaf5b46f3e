#pragma once
// Ground extraction and breadth-first segmentation of a range image (thesis
// sec 4.5.1; Bogoslavskyi & Stachniss 2016): neighbouring pixels (4-neighbour,
// azimuth wraps) belong to one object when the angle beta between the laser
// beam of the farther point and the line joining the two points exceeds a
// threshold, beta = atan2(d2 sin(alpha), d1 - d2 cos(alpha)), d1 >= d2 the
// ranges, alpha the angular step between the two beams. Small clusters are
// dropped: they give unreliable constraints.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mlidar/slam/range_image.hpp"

namespace mlidar::slam {

struct SegmentationConfig {
  double angle_threshold_deg = 60.0;  ///< beta above this joins two pixels (thesis: > 60 deg)
  double ground_slope_deg = 10.0;     ///< vertical neighbours closer than this to horizontal are ground
  double ground_below_m = 0.3;        ///< ground points lie at least this far below the sensor
  int min_cluster_points = 30;        ///< clusters this large are kept...
  int min_cluster_rows = 3;           ///< ...or ones spanning this many rows
  int min_row_span_points = 5;        ///< with at least this many points
};

/// Per-pixel labels of one range image.
struct Segmentation {
  static constexpr std::int32_t kNone = -1;  ///< empty pixel or dropped cluster
  static constexpr std::int32_t kGround = 0;
  std::vector<std::int32_t> label;        ///< kNone, kGround or cluster id >= 1
  int clusters = 0;                       ///< clusters kept
  std::vector<std::array<int, 2>> queue;  ///< breadth-first workspace (row, column), reused

  bool kept(std::size_t pixel) const { return label[pixel] != kNone; }
};

/// Labels ground (vertical neighbours nearly perpendicular to `up_lidar`, the
/// unit up direction in the LiDAR frame) then grows clusters over the rest.
/// `points` are the points the image indexes; `sorted_angles_deg` the model's
/// vertical angles ascending (row order). `out` is reused between calls.
void segment_range_image(const RangeImage& image, std::span<const Eigen::Vector3f> points, std::span<const double> sorted_angles_deg,
                         const Eigen::Vector3f& up_lidar, const SegmentationConfig& config, Segmentation& out);

}  // namespace mlidar::slam
