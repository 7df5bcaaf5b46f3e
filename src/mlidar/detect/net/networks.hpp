#pragma once
// MLOD's two networks (detector.hpp says what each does). Internal to the LibTorch component.
#include <torch/torch.h>

namespace mlidar::detect::net {

/// SECOND's RPN on a dense BEV map: block 1 (stride 2), block 2 (stride 4), an up-convolution of block 2 back to
/// stride 2 concatenated with block 1, and the anchor head (per anchor: class logit, 7 residuals, 2 direction logits).
class BevNetImpl : public torch::nn::Module {
 public:
  BevNetImpl(int in_channels, int channels, int anchors_per_cell);
  /// Block 1 of each grid: [L, C, H, W] -> [L, c, H/2, W/2].
  torch::Tensor first_block(const torch::Tensor& grids);
  /// The rest, from block 1's features [B, c, H/2, W/2]: {class [B, N], residuals [B, N, 7], direction [B, N, 2]},
  /// N = H/2 * W/2 * anchors_per_cell in (row, col, anchor) order.
  std::vector<torch::Tensor> head(const torch::Tensor& features);

 private:
  int anchors_;
  torch::nn::BatchNorm2d input_norm_{nullptr};
  torch::nn::Sequential block1_{nullptr}, block2_{nullptr}, up_{nullptr};
  torch::nn::Conv2d class_{nullptr}, residual_{nullptr}, direction_{nullptr};
};
TORCH_MODULE(BevNet);

/// PointNet over each proposal's points [P, F, N] (shared MLP, max pool) with the proposal's own features [P, G]:
/// {class logit [P], eq 6.14 residual [P, 8]}.
class RefinerImpl : public torch::nn::Module {
 public:
  RefinerImpl(int point_features, int proposal_features);
  std::vector<torch::Tensor> forward(const torch::Tensor& points, const torch::Tensor& proposals);

 private:
  torch::nn::Sequential point_mlp_{nullptr}, box_mlp_{nullptr};
  torch::nn::Linear class_{nullptr}, residual_{nullptr};
};
TORCH_MODULE(Refiner);

}  // namespace mlidar::detect::net
