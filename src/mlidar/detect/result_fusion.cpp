#include "mlidar/detect/result_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "mlidar/detect/box_coding.hpp"
#include "mlidar/eval/box_iou.hpp"

namespace mlidar::detect {
namespace {

double score_of(const io::LabelledBox& box) { return box.score.value_or(0.0); }

double logit(double p) {
  const double clamped = std::clamp(p, 1e-12, 1.0 - 1e-12);
  return std::log(clamped / (1.0 - clamped));
}

double sigmoid(double z) { return 1.0 / (1.0 + std::exp(-z)); }

/// Mean negative log-likelihood of the labels under σ(z / T), written stably: log(1 + e^{-y'a}) with a = z / T.
double negative_log_likelihood(std::span<const double> logits, std::span<const std::uint8_t> positive, double temperature) {
  double sum = 0.0;
  for (std::size_t i = 0; i < logits.size(); ++i) {
    const double margin = (positive[i] ? 1.0 : -1.0) * logits[i] / temperature;
    sum += margin > 0.0 ? std::log1p(std::exp(-margin)) : -margin + std::log1p(std::exp(margin));
  }
  return sum / static_cast<double>(std::max<std::size_t>(logits.size(), 1));
}

}  // namespace

std::vector<std::size_t> non_maximum_suppression(std::span<const io::LabelledBox> boxes, double iou_threshold) {
  std::vector<std::size_t> order(boxes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return score_of(boxes[a]) > score_of(boxes[b]); });
  std::vector<std::size_t> kept;
  for (const std::size_t candidate : order) {
    const bool suppressed = std::any_of(kept.begin(), kept.end(), [&](std::size_t k) {
      return boxes[k].object_class == boxes[candidate].object_class && eval::iou_3d(boxes[k].box, boxes[candidate].box) > iou_threshold;
    });
    if (!suppressed) kept.push_back(candidate);
  }
  return kept;
}

io::Box3D to_base(const io::Box3D& box, const SE3& T_base_lidar) {
  const Vec3 centre = T_base_lidar * box_centre(box);
  const Vec3 heading = T_base_lidar.rotation() * Vec3(std::cos(box.yaw), std::sin(box.yaw), 0.0);
  io::Box3D out = box;
  out.yaw = std::atan2(heading.y(), heading.x());
  out.center_bottom = centre - Vec3(0.0, 0.0, 0.5 * box.height);
  return out;
}

std::vector<io::LabelledBox> fuse_results(std::span<const LidarDetections> lidars, double iou_threshold) {
  std::vector<io::LabelledBox> pooled;
  for (const LidarDetections& lidar : lidars) {
    for (io::LabelledBox box : lidar.boxes) {
      box.box = to_base(box.box, lidar.T_base_lidar);
      box.score = sigmoid(logit(score_of(box)) / lidar.temperature);
      pooled.push_back(box);
    }
  }
  std::vector<io::LabelledBox> fused;
  for (const std::size_t k : non_maximum_suppression(pooled, iou_threshold)) fused.push_back(pooled[k]);
  return fused;
}

double fit_temperature(std::span<const double> logits, std::span<const std::uint8_t> positive) {
  // Golden-section search on u = log T: the NLL is convex in 1/T, so unimodal in u.
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double lo = std::log(1e-2), hi = std::log(1e2);
  double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
  double fa = negative_log_likelihood(logits, positive, std::exp(a));
  double fb = negative_log_likelihood(logits, positive, std::exp(b));
  for (int iteration = 0; iteration < 100 && hi - lo > 1e-9; ++iteration) {
    if (fa < fb) {  // the minimum lies in [lo, b]
      hi = b;
      b = a;
      fb = fa;
      a = hi - ratio * (hi - lo);
      fa = negative_log_likelihood(logits, positive, std::exp(a));
    } else {  // in [a, hi]
      lo = a;
      a = b;
      fa = fb;
      b = lo + ratio * (hi - lo);
      fb = negative_log_likelihood(logits, positive, std::exp(b));
    }
  }
  return std::exp(0.5 * (lo + hi));
}

}  // namespace mlidar::detect
