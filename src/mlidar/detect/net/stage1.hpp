#pragma once
// Stage 1's data, loss and decoding around BevNet (internal to the LibTorch component).
#include <vector>

#include <torch/torch.h>

#include "mlidar/detect/detection_frames.hpp"
#include "mlidar/detect/model_folder.hpp"
#include "mlidar/detect/net/networks.hpp"

namespace mlidar::detect::net {

/// The BEV grids stage 1 reads from a frame whose lidars are the model's: [1, C, H, W] for none and input fusion, one
/// per LiDAR [L, C, H, W] for feature and result fusion.
torch::Tensor stage1_grids(const DetectionFrame& frame, Fusion fusion, const BevGridConfig& grid);

/// {class [B, N], residuals [B, N, 7], direction [B, N, 2]}: B = 1, or one per LiDAR for result fusion.
std::vector<torch::Tensor> run_stage1(BevNet& net, const torch::Tensor& grids, Fusion fusion);

/// The training targets of one batch item: the boxes of the class with at least one point in `points` (the input it
/// sees) are targets; anchors near boxes it cannot see are ignored rather than taught as background.
struct Stage1Targets {
  torch::Tensor label;      ///< [N] 1 / 0 / -1 (ignored)
  torch::Tensor residual;   ///< [N, 7]
  torch::Tensor direction;  ///< [N] 0 / 1: the box's heading is the decoded one turned by half a turn
  long positives = 0;
};
Stage1Targets stage1_targets(std::span<const io::Box3D> boxes, std::span<const Vec3> points, const DetectConfig& config);

/// Focal loss FL(p_t) = -alpha_t (1 - p_t)^gamma log p_t (Lin et al. 2017) of each logit against its label (1
/// positive, 0 negative, -1 ignored: no loss), summed. Both stages classify with it.
torch::Tensor focal_loss_sum(const torch::Tensor& logits, const torch::Tensor& labels, double alpha, double gamma);

struct Stage1Loss {
  torch::Tensor total, classification, regression, direction;
};
/// Focal loss on the class (alpha, gamma), smooth-L1 on the positives' residuals (the heading as SECOND's sine
/// difference), cross-entropy on their direction;
/// each summed and divided by the positives (at least one). `item` selects the batch item of `output`.
Stage1Loss stage1_loss(const std::vector<torch::Tensor>& output, long item, const Stage1Targets& targets, const Stage1TrainConfig& config);

/// A decoded box with its stage-1 logit.
struct Proposal {
  io::Box3D box;
  double score = 0.0;  ///< sigma(logit)
  double logit = 0.0;
};
/// Batch item `item`'s boxes: anchors scoring at least `score_threshold` (the best `pre_nms`), decoded, NMS on 3D IoU,
/// at most `max_detections`, by descending score.
std::vector<Proposal> decode_stage1(const std::vector<torch::Tensor>& output, long item, const DetectConfig& config, double score_threshold);

/// Stage 1 run on a frame (eval mode, no gradients): the decoded boxes at `score_threshold`; with result fusion each
/// LiDAR's boxes, their scores recalibrated by its temperature (one per frame LiDAR), fused by NMS (eq 6.11).
std::vector<Proposal> stage1_proposals(BevNet& net, const DetectionFrame& frame, Fusion fusion, const DetectConfig& config,
                                       const std::vector<double>& temperatures, double score_threshold);

}  // namespace mlidar::detect::net
