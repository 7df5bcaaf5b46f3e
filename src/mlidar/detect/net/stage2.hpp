#pragma once
// Stage 2's data, loss and refinement around the Refiner (internal to the LibTorch component).
#include <random>
#include <vector>

#include <torch/torch.h>

#include "mlidar/detect/detection_frames.hpp"
#include "mlidar/detect/net/networks.hpp"
#include "mlidar/detect/net/stage1.hpp"

namespace mlidar::detect::net {

inline constexpr int kPointFeatures = 4;     ///< canonical x, y, z (eq 6.12-6.13) and log tr(Xi)
inline constexpr int kProposalFeatures = 5;  ///< stage-1 score, l, w, h relative to the anchor, log(1 + points)

/// PointNet's input for each proposal: {points [P, 4, N], proposal features [P, 5]} and the largest tr(Xi) among each
/// proposal's points (eq 6.16). N = config.points: a proposal with more points keeps evenly spaced ones (cloud
/// order), one with fewer repeats them.
struct Stage2Input {
  torch::Tensor points, proposals;
  std::vector<double> max_uncertainty;
};
Stage2Input stage2_input(const LidarPoints& cloud, std::span<const Proposal> proposals, const DetectConfig& config);

/// Training targets: each proposal's best 3D IoU with a true box decides positive (> positive_iou), negative
/// (< negative_iou) or ignored; positives regress eq 6.14's residual to that box.
struct Stage2Targets {
  torch::Tensor label;     ///< [P] 1 / 0 / -1
  torch::Tensor residual;  ///< [P, 8]
  long positives = 0;
};
Stage2Targets stage2_targets(std::span<const Proposal> proposals, std::span<const io::Box3D> boxes, const Stage2Config& config);

struct Stage2Loss {
  torch::Tensor total, classification, regression, uncertainty;
};
/// eq 6.15-6.17: L = L_reg + eta L_cls + lambda L_uct, L_cls focal (alpha 0.25, gamma 2), L_reg smooth-L1 over the
/// positives, L_uct = sum_i exp(1 - f[max_j tr(Xi_j)]) ||u'_i||_2 with f clamping to [1e-3, 0.5] and u' the regressed
/// residual without its cosine; each sum divided by the positives (at least one).
Stage2Loss stage2_loss(const std::vector<torch::Tensor>& output, const Stage2Targets& targets, const Stage2Input& input, const Stage2Config& config);

/// Training proposals besides stage 1's: each true box moved by up to a quarter of its size and turned by up to 10°,
/// `count` times (positives and near misses for the refiner to learn from).
std::vector<Proposal> jittered_truths(std::span<const io::Box3D> boxes, int count, std::mt19937_64& rng);

/// The refined boxes: each proposal decoded from its regressed residual, scored by stage 2, then NMS on 3D IoU.
std::vector<io::LabelledBox> refine(const std::vector<torch::Tensor>& output, std::span<const Proposal> proposals, const DetectConfig& config);

}  // namespace mlidar::detect::net
