#pragma once
// Stage 1's training targets (thesis 6.5.1 builds on SECOND, whose head is anchor-based; we keep anchors so that the
// proposals are the thesis's): at the centre of every cell of the head's BEV grid, one anchor per yaw (0 and 90°)
// of a class's mean size. An anchor is positive when its BEV IoU with a ground-truth box reaches `positive_iou`,
// negative below `negative_iou`, ignored between; each box's best anchor is positive too (SECOND's rule, car 0.6 /
// 0.45). Positives regress SECOND's residuals:
//   Δx = (x_g − x_a)/d_a, Δy = (y_g − y_a)/d_a, Δz = (z_g − z_a)/h_a   (d_a = √(l_a² + w_a²), centres)
//   Δl = log(l_g/l_a), Δw = log(w_g/w_a), Δh = log(h_g/h_a), Δθ = θ_g − θ_a wrapped to [−π/2, π/2) (a box and its
//   180° turn are the same box; a direction classifier is the network's business)
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mlidar/detect/bev_grid.hpp"
#include "mlidar/io/detection_labels.hpp"

namespace mlidar::detect {

struct AnchorConfig {
  double length = 3.9, width = 1.6, height = 1.56;  ///< the class's mean size (SECOND's car)
  double bottom_z = 0.0;  ///< anchors' bottom in the base frame: the ground (0 for a vehicle frame on the ground, as lyft's)
  std::array<double, 2> yaws = {0.0, 1.5707963267948966};
  int stride = 2;  ///< head cells per BEV cell side: the head's grid is the BEV grid downsampled by this
  double positive_iou = 0.6;
  double negative_iou = 0.45;
};

using AnchorResidual = std::array<double, 7>;

struct AnchorTargets {
  int rows = 0, cols = 0, yaws = 0;     ///< the head's grid; anchor index = (row * cols + col) * yaws + yaw
  std::vector<std::int8_t> label;       ///< 1 positive, 0 negative, -1 ignored
  std::vector<int> matched_box;         ///< the box a positive regresses to, else -1
  std::vector<AnchorResidual> residual; ///< SECOND's residuals of positives (zeros elsewhere)
  int positives() const;
};

/// The anchor at a head cell and yaw index.
io::Box3D anchor_box(int row, int col, int yaw_index, const BevGridConfig& grid, const AnchorConfig& anchors);

AnchorResidual encode_anchor(const io::Box3D& box, const io::Box3D& anchor);
io::Box3D decode_anchor(const AnchorResidual& residual, const io::Box3D& anchor);

/// Labels and residuals of every anchor of the head's grid for the ground-truth boxes of one frame (base frame, one
/// class). Only anchors within reach of a box are compared with it.
AnchorTargets assign_anchors(std::span<const io::Box3D> boxes, const BevGridConfig& grid, const AnchorConfig& anchors);

}  // namespace mlidar::detect
