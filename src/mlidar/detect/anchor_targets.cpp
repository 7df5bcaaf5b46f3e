#include "mlidar/detect/anchor_targets.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mlidar/detect/box_coding.hpp"
#include "mlidar/eval/box_iou.hpp"

namespace mlidar::detect {
namespace {

/// θ wrapped to [−π/2, π/2).
double wrap_half_turn(double angle) {
  const double wrapped = std::fmod(angle + std::numbers::pi / 2, std::numbers::pi);
  return (wrapped < 0.0 ? wrapped + std::numbers::pi : wrapped) - std::numbers::pi / 2;
}

int head_cells(double from, double to, const BevGridConfig& grid, int stride) {
  return static_cast<int>(std::ceil((to - from) / (grid.cell * stride) - 1e-9));
}

}  // namespace

int AnchorTargets::positives() const { return static_cast<int>(std::count(label.begin(), label.end(), std::int8_t{1})); }

io::Box3D anchor_box(int row, int col, int yaw_index, const BevGridConfig& grid, const AnchorConfig& anchors) {
  const double side = grid.cell * anchors.stride;
  return {Vec3(grid.x_min + (col + 0.5) * side, grid.y_min + (row + 0.5) * side, anchors.bottom_z), anchors.length, anchors.width,
          anchors.height, anchors.yaws[static_cast<std::size_t>(yaw_index)]};
}

AnchorResidual encode_anchor(const io::Box3D& box, const io::Box3D& anchor) {
  const double diagonal = std::hypot(anchor.length, anchor.width);
  return {(box.center_bottom.x() - anchor.center_bottom.x()) / diagonal,
          (box.center_bottom.y() - anchor.center_bottom.y()) / diagonal,
          (box_centre(box).z() - box_centre(anchor).z()) / anchor.height,
          std::log(box.length / anchor.length),
          std::log(box.width / anchor.width),
          std::log(box.height / anchor.height),
          wrap_half_turn(box.yaw - anchor.yaw)};
}

io::Box3D decode_anchor(const AnchorResidual& r, const io::Box3D& anchor) {
  const double diagonal = std::hypot(anchor.length, anchor.width);
  io::Box3D box;
  box.length = anchor.length * std::exp(r[3]);
  box.width = anchor.width * std::exp(r[4]);
  box.height = anchor.height * std::exp(r[5]);
  box.yaw = anchor.yaw + r[6];
  const double z = box_centre(anchor).z() + r[2] * anchor.height;
  box.center_bottom = Vec3(anchor.center_bottom.x() + r[0] * diagonal, anchor.center_bottom.y() + r[1] * diagonal, z - 0.5 * box.height);
  return box;
}

AnchorTargets assign_anchors(std::span<const io::Box3D> boxes, const BevGridConfig& grid, const AnchorConfig& anchors) {
  AnchorTargets targets;
  targets.rows = head_cells(grid.y_min, grid.y_max, grid, anchors.stride);
  targets.cols = head_cells(grid.x_min, grid.x_max, grid, anchors.stride);
  targets.yaws = static_cast<int>(anchors.yaws.size());
  const std::size_t count = static_cast<std::size_t>(targets.rows) * targets.cols * targets.yaws;
  std::vector<double> best_iou(count, 0.0);
  targets.matched_box.assign(count, -1);
  const double side = grid.cell * anchors.stride;
  const double anchor_reach = 0.5 * std::hypot(anchors.length, anchors.width);
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const io::Box3D& box = boxes[b];
    const double reach = 0.5 * std::hypot(box.length, box.width) + anchor_reach;  // beyond it the footprints cannot meet
    const int col_lo = std::max(0, static_cast<int>(std::floor((box.center_bottom.x() - reach - grid.x_min) / side)));
    const int col_hi = std::min(targets.cols - 1, static_cast<int>(std::floor((box.center_bottom.x() + reach - grid.x_min) / side)));
    const int row_lo = std::max(0, static_cast<int>(std::floor((box.center_bottom.y() - reach - grid.y_min) / side)));
    const int row_hi = std::min(targets.rows - 1, static_cast<int>(std::floor((box.center_bottom.y() + reach - grid.y_min) / side)));
    std::size_t best_anchor = count;
    double best_for_box = 0.0;
    for (int row = row_lo; row <= row_hi; ++row) {
      for (int col = col_lo; col <= col_hi; ++col) {
        for (int yaw = 0; yaw < targets.yaws; ++yaw) {
          const std::size_t a = (static_cast<std::size_t>(row) * targets.cols + col) * targets.yaws + yaw;
          const double iou = eval::bev_iou(box, anchor_box(row, col, yaw, grid, anchors));
          if (iou > best_iou[a]) {
            best_iou[a] = iou;
            targets.matched_box[a] = static_cast<int>(b);
          }
          if (iou > best_for_box) {
            best_for_box = iou;
            best_anchor = a;
          }
        }
      }
    }
    if (best_anchor < count) {  // SECOND: each box's best anchor is positive whatever its IoU
      best_iou[best_anchor] = std::max(best_iou[best_anchor], anchors.positive_iou);
      targets.matched_box[best_anchor] = static_cast<int>(b);
    }
  }
  targets.label.assign(count, 0);
  targets.residual.assign(count, AnchorResidual{});
  for (std::size_t a = 0; a < count; ++a) {
    if (best_iou[a] >= anchors.positive_iou) {
      targets.label[a] = 1;
      const int yaw = static_cast<int>(a % targets.yaws);
      const int cell = static_cast<int>(a / targets.yaws);
      const io::Box3D anchor = anchor_box(cell / targets.cols, cell % targets.cols, yaw, grid, anchors);
      targets.residual[a] = encode_anchor(boxes[static_cast<std::size_t>(targets.matched_box[a])], anchor);
    } else if (best_iou[a] >= anchors.negative_iou) {
      targets.label[a] = -1;
      targets.matched_box[a] = -1;
    } else {
      targets.matched_box[a] = -1;
    }
  }
  return targets;
}

}  // namespace mlidar::detect
