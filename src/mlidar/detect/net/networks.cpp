#include "mlidar/detect/net/networks.hpp"

namespace mlidar::detect::net {
namespace nn = torch::nn;

namespace {

/// A block: a 3x3 convolution of `in` channels at `stride`, then `repeats` more at stride 1, each with BatchNorm and ReLU.
nn::Sequential conv_block(int in, int out, int stride, int repeats) {
  nn::Sequential block;
  for (int k = 0; k <= repeats; ++k) {
    block->push_back(nn::Conv2d(nn::Conv2dOptions(k == 0 ? in : out, out, 3).stride(k == 0 ? stride : 1).padding(1).bias(false)));
    block->push_back(nn::BatchNorm2d(out));
    block->push_back(nn::ReLU());
  }
  return block;
}

}  // namespace

BevNetImpl::BevNetImpl(int in_channels, int channels, int anchors_per_cell) : anchors_(anchors_per_cell) {
  const int c = channels;
  input_norm_ = register_module("input_norm", nn::BatchNorm2d(in_channels));
  block1_ = register_module("block1", conv_block(in_channels, c, 2, 2));
  block2_ = register_module("block2", conv_block(c, 2 * c, 2, 2));
  up_ = register_module("up", nn::Sequential(nn::ConvTranspose2d(nn::ConvTranspose2dOptions(2 * c, c, 2).stride(2).bias(false)),
                                             nn::BatchNorm2d(c), nn::ReLU()));
  class_ = register_module("score", nn::Conv2d(nn::Conv2dOptions(2 * c, anchors_, 1)));
  residual_ = register_module("residual", nn::Conv2d(nn::Conv2dOptions(2 * c, 7 * anchors_, 1)));
  direction_ = register_module("direction", nn::Conv2d(nn::Conv2dOptions(2 * c, 2 * anchors_, 1)));
  // Focal loss's prior (Lin et al. 2017): start every anchor at probability 0.01 so that the many negatives do not
  // swamp the first steps.
  torch::NoGradGuard no_grad;
  class_->bias.fill_(-std::log((1.0 - 0.01) / 0.01));
}

torch::Tensor BevNetImpl::first_block(const torch::Tensor& grids) { return block1_->forward(input_norm_->forward(grids)); }

std::vector<torch::Tensor> BevNetImpl::head(const torch::Tensor& features) {
  const torch::Tensor x = torch::cat({features, up_->forward(block2_->forward(features))}, 1);
  const long batch = x.size(0);
  // [B, k A, H, W] -> [B, H, W, A k] -> [B, N, k]: anchor index (row W + col) A + a, as detect/anchor_targets numbers them.
  const auto per_anchor = [&](const torch::Tensor& map, long k) { return map.permute({0, 2, 3, 1}).reshape({batch, -1, k}); };
  return {per_anchor(class_->forward(x), 1).squeeze(2), per_anchor(residual_->forward(x), 7), per_anchor(direction_->forward(x), 2)};
}

RefinerImpl::RefinerImpl(int point_features, int proposal_features) {
  point_mlp_ = register_module(
      "point_mlp", nn::Sequential(nn::Conv1d(nn::Conv1dOptions(point_features, 64, 1).bias(false)), nn::BatchNorm1d(64), nn::ReLU(),
                                  nn::Conv1d(nn::Conv1dOptions(64, 128, 1).bias(false)), nn::BatchNorm1d(128), nn::ReLU(),
                                  nn::Conv1d(nn::Conv1dOptions(128, 256, 1).bias(false)), nn::BatchNorm1d(256), nn::ReLU()));
  box_mlp_ = register_module("box_mlp", nn::Sequential(nn::Linear(256 + proposal_features, 256), nn::ReLU(), nn::Linear(256, 128), nn::ReLU()));
  class_ = register_module("score", nn::Linear(128, 1));
  residual_ = register_module("residual", nn::Linear(128, 8));
}

std::vector<torch::Tensor> RefinerImpl::forward(const torch::Tensor& points, const torch::Tensor& proposals) {
  const torch::Tensor global = std::get<0>(point_mlp_->forward(points).max(2));  // PointNet's symmetric max pool
  const torch::Tensor x = box_mlp_->forward(torch::cat({global, proposals}, 1));
  return {class_->forward(x).squeeze(1), residual_->forward(x)};
}

}  // namespace mlidar::detect::net
