#pragma once
// Result fusion (thesis 6.5.1, eq 6.11): each LiDAR's detections moved into the base frame, pooled and reduced by
// non-maximum suppression on 3D IoU; the scores of different detectors first made comparable by temperature scaling
// (Guo et al. 2017: p = σ(z / T), one T per detector fitted on held-out detections by their negative log-likelihood).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mlidar/core/se3.hpp"
#include "mlidar/io/detection_labels.hpp"

namespace mlidar::detect {

/// Indices of the boxes kept by greedy NMS: by descending score (ties by index), a box is dropped when its 3D IoU
/// with a kept box of the same class exceeds `iou_threshold`. Boxes without a score count as 0.
std::vector<std::size_t> non_maximum_suppression(std::span<const io::LabelledBox> boxes, double iou_threshold);

/// A box of a LiDAR's frame in the base frame: its centre moved by T_base_lidar, its heading turned by it and
/// projected on the base's xy plane (upright boxes stay upright; a LiDAR's roll or pitch only moves the centre).
io::Box3D to_base(const io::Box3D& box_in_lidar, const SE3& T_base_lidar);

/// One LiDAR's detections, in its own frame, with the temperature that calibrates its scores.
struct LidarDetections {
  SE3 T_base_lidar;
  std::vector<io::LabelledBox> boxes;  ///< scores are the detector's probabilities σ(z)
  double temperature = 1.0;
};

/// eq 6.11: every LiDAR's boxes in the base frame, scores recalibrated to σ(logit(p) / T), then NMS at `iou_threshold`.
std::vector<io::LabelledBox> fuse_results(std::span<const LidarDetections> lidars, double iou_threshold);

/// The temperature T > 0 minimising the negative log-likelihood of labels (1 positive, 0 negative) under p = σ(z / T) (golden-section
/// search on log T in [1e-2, 1e2]; the NLL is convex in 1/T).
double fit_temperature(std::span<const double> logits, std::span<const std::uint8_t> positive);

}  // namespace mlidar::detect
