#include "mlidar/detect/net/stage1.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mlidar/detect/anchor_targets.hpp"
#include "mlidar/detect/bev_grid.hpp"
#include "mlidar/detect/proposal_points.hpp"
#include "mlidar/detect/result_fusion.hpp"

namespace mlidar::detect::net {
namespace {

torch::Tensor grid_tensor(const LidarPoints& lidar, const BevGridConfig& config) {
  const BevGrid grid = make_bev_grid(lidar.points, lidar.intensity, lidar.uncertainty, config);
  return torch::from_blob(const_cast<float*>(grid.features.data()), {kBevChannels, grid.rows, grid.cols}, torch::kFloat32).clone();
}

}  // namespace

torch::Tensor stage1_grids(const DetectionFrame& frame, Fusion fusion, const BevGridConfig& grid) {
  if (fusion == Fusion::kInput) return grid_tensor(merge_lidars(frame), grid).unsqueeze(0);
  std::vector<torch::Tensor> grids;
  for (const LidarPoints& lidar : frame.lidars) grids.push_back(grid_tensor(lidar, grid));
  return torch::stack(grids);
}

std::vector<torch::Tensor> run_stage1(BevNet& net, const torch::Tensor& grids, Fusion fusion) {
  torch::Tensor features = net->first_block(grids);
  if (fusion == Fusion::kFeature) features = std::get<0>(features.max(0, /*keepdim=*/true));  // eq 6.10
  return net->head(features);
}

Stage1Targets stage1_targets(std::span<const io::Box3D> boxes, std::span<const Vec3> points, const DetectConfig& config) {
  std::vector<io::Box3D> seen, unseen;
  for (const io::Box3D& box : boxes) {
    (proposal_points(points, {}, box, 0.0).indices.empty() ? unseen : seen).push_back(box);
  }
  const AnchorTargets targets = assign_anchors(seen, config.grid, config.anchors);
  const AnchorTargets hidden = assign_anchors(unseen, config.grid, config.anchors);
  const long count = static_cast<long>(targets.label.size());
  Stage1Targets out;
  out.label = torch::empty({count}, torch::kFloat32);
  out.residual = torch::zeros({count, 7}, torch::kFloat32);
  out.direction = torch::zeros({count}, torch::kLong);
  auto label = out.label.accessor<float, 1>();
  auto residual = out.residual.accessor<float, 2>();
  auto direction = out.direction.accessor<long, 1>();
  for (long a = 0; a < count; ++a) {
    const auto i = static_cast<std::size_t>(a);
    label[a] = targets.label[i] == 0 && hidden.label[i] != 0 ? -1.0f : targets.label[i];
    if (targets.label[i] != 1) continue;
    ++out.positives;
    for (int k = 0; k < 7; ++k) residual[a][k] = static_cast<float>(targets.residual[i][static_cast<std::size_t>(k)]);
    const double anchor_yaw = config.anchors.yaws[i % config.anchors.yaws.size()];
    const double decoded_yaw = anchor_yaw + targets.residual[i][6];
    const double turn = std::remainder(seen[static_cast<std::size_t>(targets.matched_box[i])].yaw - decoded_yaw, 2.0 * std::numbers::pi);
    direction[a] = std::abs(turn) > std::numbers::pi / 2 ? 1 : 0;
  }
  return out;
}

torch::Tensor focal_loss_sum(const torch::Tensor& logits, const torch::Tensor& labels, double alpha, double gamma) {
  const torch::Tensor y = labels.clamp_min(0.0);
  const torch::Tensor p = torch::sigmoid(logits);
  const torch::Tensor p_t = y * p + (1 - y) * (1 - p);
  const torch::Tensor alpha_t = y * alpha + (1 - y) * (1 - alpha);
  const torch::Tensor bce = torch::binary_cross_entropy_with_logits(logits, y, {}, {}, torch::Reduction::None);
  return (alpha_t * (1 - p_t).pow(gamma) * bce * labels.ge(0)).sum();
}

Stage1Loss stage1_loss(const std::vector<torch::Tensor>& output, long item, const Stage1Targets& targets, const Stage1TrainConfig& config) {
  const torch::Tensor positive = targets.label.eq(1);
  const double normalizer = std::max<long>(1, targets.positives);
  Stage1Loss loss;
  loss.classification = focal_loss_sum(output[0][item], targets.label, config.focal_alpha, config.focal_gamma) / normalizer;
  if (targets.positives > 0) {
    const torch::Tensor index = positive.nonzero().squeeze(1);
    // SECOND's sine difference: the heading residual compared as sin(p - t) = sin p cos t - cos p sin t, smooth across
    // the half-turn wrap of the targets (the direction classifier tells the half turns apart).
    const torch::Tensor predicted = output[1][item].index_select(0, index);
    const torch::Tensor target = targets.residual.index_select(0, index);
    const torch::Tensor p_yaw = predicted.narrow(1, 6, 1), t_yaw = target.narrow(1, 6, 1);
    const torch::Tensor lhs = torch::cat({predicted.narrow(1, 0, 6), torch::sin(p_yaw) * torch::cos(t_yaw)}, 1);
    const torch::Tensor rhs = torch::cat({target.narrow(1, 0, 6), torch::cos(p_yaw) * torch::sin(t_yaw)}, 1);
    loss.regression = torch::smooth_l1_loss(lhs, rhs, torch::Reduction::Sum, 1.0 / 9.0) / normalizer;
    loss.direction = torch::cross_entropy_loss(output[2][item].index_select(0, index), targets.direction.index_select(0, index),
                                               {}, torch::Reduction::Sum) / normalizer;
  } else {
    loss.regression = torch::zeros({}, torch::kFloat32);
    loss.direction = torch::zeros({}, torch::kFloat32);
  }
  loss.total = loss.classification + config.regression_weight * loss.regression + config.direction_weight * loss.direction;
  return loss;
}

std::vector<Proposal> decode_stage1(const std::vector<torch::Tensor>& output, long item, const DetectConfig& config, double score_threshold) {
  const torch::Tensor logits = output[0][item].detach();
  const long candidates = std::min<long>(config.inference.pre_nms, logits.size(0));
  const auto [top_logits, top_index] = logits.topk(candidates);
  const torch::Tensor residuals = output[1][item].detach().index_select(0, top_index);
  const torch::Tensor directions = output[2][item].detach().index_select(0, top_index).argmax(1);
  const auto logit = top_logits.accessor<float, 1>();
  const auto index = top_index.accessor<long, 1>();
  const auto residual = residuals.accessor<float, 2>();
  const auto direction = directions.accessor<long, 1>();
  const long cols = static_cast<long>(std::llround((config.grid.x_max - config.grid.x_min) / (config.grid.cell * config.anchors.stride)));
  const long yaws = static_cast<long>(config.anchors.yaws.size());
  std::vector<Proposal> candidates_kept;
  std::vector<io::LabelledBox> boxes;
  for (long k = 0; k < candidates; ++k) {
    const double score = 1.0 / (1.0 + std::exp(-static_cast<double>(logit[k])));
    if (score < score_threshold) break;  // topk sorts by logit
    const long a = index[k];
    const io::Box3D anchor = anchor_box(static_cast<int>(a / yaws / cols), static_cast<int>((a / yaws) % cols), static_cast<int>(a % yaws),
                                        config.grid, config.anchors);
    AnchorResidual r;
    for (int j = 0; j < 7; ++j) r[static_cast<std::size_t>(j)] = residual[k][j];
    io::Box3D box = decode_anchor(r, anchor);
    if (direction[k] == 1) box.yaw += std::numbers::pi;
    box.yaw = std::remainder(box.yaw, 2.0 * std::numbers::pi);
    if (!(box.length > 0.0 && box.width > 0.0 && box.height > 0.0) || !box.center_bottom.allFinite()) continue;
    candidates_kept.push_back({box, score, logit[k]});
    boxes.push_back({config.object_class, box, score, 0});
  }
  std::vector<Proposal> kept;
  for (const std::size_t i : non_maximum_suppression(boxes, config.inference.nms_iou)) {
    if (static_cast<int>(kept.size()) == config.inference.max_detections) break;
    kept.push_back(candidates_kept[i]);
  }
  return kept;
}

std::vector<Proposal> stage1_proposals(BevNet& net, const DetectionFrame& frame, Fusion fusion, const DetectConfig& config,
                                       const std::vector<double>& temperatures, double score_threshold) {
  torch::NoGradGuard no_grad;
  const std::vector<torch::Tensor> output = run_stage1(net, stage1_grids(frame, fusion, config.grid), fusion);
  if (fusion != Fusion::kResult) return decode_stage1(output, 0, config, score_threshold);
  std::vector<LidarDetections> lidars;
  for (long item = 0; item < output[0].size(0); ++item) {
    LidarDetections detections;  // the grids are in the base frame already: T_base_lidar stays the identity
    detections.temperature = temperatures.at(static_cast<std::size_t>(item));
    for (const Proposal& proposal : decode_stage1(output, item, config, score_threshold)) {
      detections.boxes.push_back({config.object_class, proposal.box, proposal.score, 0});
    }
    lidars.push_back(std::move(detections));
  }
  std::vector<Proposal> fused;
  for (const io::LabelledBox& box : fuse_results(lidars, config.inference.nms_iou)) {
    const double p = std::clamp(box.score.value_or(0.0), 1e-9, 1.0 - 1e-9);
    fused.push_back({box.box, p, std::log(p / (1.0 - p))});
    if (static_cast<int>(fused.size()) == config.inference.max_detections) break;
  }
  return fused;
}

}  // namespace mlidar::detect::net
