#include "mlidar/detect/net/stage2.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mlidar/detect/box_coding.hpp"
#include "mlidar/detect/proposal_points.hpp"
#include "mlidar/detect/result_fusion.hpp"
#include "mlidar/eval/box_iou.hpp"

namespace mlidar::detect::net {

Stage2Input stage2_input(const LidarPoints& cloud, std::span<const Proposal> proposals, const DetectConfig& config) {
  const long count = static_cast<long>(proposals.size());
  const int n = config.stage2.points;
  Stage2Input input;
  input.points = torch::zeros({count, kPointFeatures, n}, torch::kFloat32);
  input.proposals = torch::zeros({count, kProposalFeatures}, torch::kFloat32);
  auto points = input.points.accessor<float, 3>();
  auto features = input.proposals.accessor<float, 2>();
  for (long p = 0; p < count; ++p) {
    const Proposal& proposal = proposals[static_cast<std::size_t>(p)];
    const ProposalPoints inside = proposal_points(cloud.points, cloud.uncertainty, proposal.box, config.stage2.margin_m);
    const std::size_t m = inside.canonical.size();
    double max_uncertainty = 0.0;
    for (int k = 0; k < n && m > 0; ++k) {
      const std::size_t i = m >= static_cast<std::size_t>(n) ? k * m / n : k % m;  // evenly spaced, or repeated
      const Vec3& q = inside.canonical[i];
      points[p][0][k] = static_cast<float>(q.x()), points[p][1][k] = static_cast<float>(q.y()), points[p][2][k] = static_cast<float>(q.z());
      points[p][3][k] = static_cast<float>(std::log(std::max(inside.uncertainty[i], 1e-6)));
    }
    for (const double u : inside.uncertainty) max_uncertainty = std::max(max_uncertainty, u);
    input.max_uncertainty.push_back(max_uncertainty);
    features[p][0] = static_cast<float>(proposal.score);
    features[p][1] = static_cast<float>(proposal.box.length / config.anchors.length);
    features[p][2] = static_cast<float>(proposal.box.width / config.anchors.width);
    features[p][3] = static_cast<float>(proposal.box.height / config.anchors.height);
    features[p][4] = static_cast<float>(std::log1p(static_cast<double>(m)));
  }
  return input;
}

Stage2Targets stage2_targets(std::span<const Proposal> proposals, std::span<const io::Box3D> boxes, const Stage2Config& config) {
  const long count = static_cast<long>(proposals.size());
  Stage2Targets targets;
  targets.label = torch::zeros({count}, torch::kFloat32);
  targets.residual = torch::zeros({count, 8}, torch::kFloat32);
  auto label = targets.label.accessor<float, 1>();
  auto residual = targets.residual.accessor<float, 2>();
  for (long p = 0; p < count; ++p) {
    const io::Box3D& proposal = proposals[static_cast<std::size_t>(p)].box;
    double best = 0.0;
    std::size_t best_box = 0;
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const double iou = eval::iou_3d(proposal, boxes[b]);
      if (iou > best) best = iou, best_box = b;
    }
    label[p] = best > config.positive_iou ? 1.0f : (best < config.negative_iou ? 0.0f : -1.0f);
    if (label[p] != 1.0f) continue;
    ++targets.positives;
    const Residual u = encode(boxes[best_box], proposal);  // eq 6.14
    for (int k = 0; k < 8; ++k) residual[p][k] = static_cast<float>(u[static_cast<std::size_t>(k)]);
  }
  return targets;
}

Stage2Loss stage2_loss(const std::vector<torch::Tensor>& output, const Stage2Targets& targets, const Stage2Input& input, const Stage2Config& config) {
  const double normalizer = std::max<long>(1, targets.positives);
  Stage2Loss loss;
  loss.classification = focal_loss_sum(output[0], targets.label, 0.25, 2.0) / normalizer;  // eq 6.15, f_cls
  if (targets.positives > 0) {
    const torch::Tensor index = targets.label.eq(1).nonzero().squeeze(1);
    const torch::Tensor u = output[1].index_select(0, index);
    loss.regression = torch::smooth_l1_loss(u, targets.residual.index_select(0, index), torch::Reduction::Sum) / normalizer;  // eq 6.15, f_reg
    std::vector<float> weights;
    const auto rows = index.accessor<long, 1>();
    for (long k = 0; k < index.size(0); ++k) {
      const double f = std::clamp(input.max_uncertainty[static_cast<std::size_t>(rows[k])], 1e-3, 0.5);
      weights.push_back(static_cast<float>(std::exp(1.0 - f)));  // eq 6.16
    }
    const torch::Tensor weight = torch::tensor(weights, torch::kFloat32);
    loss.uncertainty = (weight * u.narrow(1, 0, 7).norm(2, 1)).sum() / normalizer;
  } else {
    loss.regression = torch::zeros({}, torch::kFloat32);
    loss.uncertainty = torch::zeros({}, torch::kFloat32);
  }
  loss.total = loss.regression + config.eta * loss.classification + config.lambda * loss.uncertainty;  // eq 6.17
  return loss;
}

std::vector<Proposal> jittered_truths(std::span<const io::Box3D> boxes, int count, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Proposal> out;
  for (const io::Box3D& box : boxes) {
    for (int k = 0; k < count; ++k) {
      io::Box3D moved = box;
      moved.center_bottom += Vec3(0.25 * box.length * unit(rng), 0.25 * box.width * unit(rng), 0.25 * box.height * unit(rng));
      moved.length *= 1.0 + 0.15 * unit(rng), moved.width *= 1.0 + 0.15 * unit(rng), moved.height *= 1.0 + 0.15 * unit(rng);
      moved.yaw += 10.0 * std::numbers::pi / 180.0 * unit(rng);
      out.push_back({moved, 0.5 + 0.5 * std::abs(unit(rng)), 0.0});
    }
  }
  return out;
}

std::vector<io::LabelledBox> refine(const std::vector<torch::Tensor>& output, std::span<const Proposal> proposals, const DetectConfig& config) {
  const torch::Tensor scores = torch::sigmoid(output[0].detach());
  const torch::Tensor residuals = output[1].detach().to(torch::kFloat64);
  const auto score = scores.accessor<float, 1>();
  const auto residual = residuals.accessor<double, 2>();
  std::vector<io::LabelledBox> boxes;
  for (std::size_t p = 0; p < proposals.size(); ++p) {
    Residual u;
    for (int k = 0; k < 8; ++k) u[static_cast<std::size_t>(k)] = residual[static_cast<long>(p)][k];
    const io::Box3D box = decode(u, proposals[p].box);
    if (!(box.length > 0.0 && box.width > 0.0 && box.height > 0.0) || !box.center_bottom.allFinite()) continue;
    boxes.push_back({config.object_class, box, static_cast<double>(score[static_cast<long>(p)]), 0});
  }
  std::vector<io::LabelledBox> kept;
  for (const std::size_t i : non_maximum_suppression(boxes, config.inference.nms_iou)) kept.push_back(boxes[i]);
  return kept;
}

}  // namespace mlidar::detect::net
