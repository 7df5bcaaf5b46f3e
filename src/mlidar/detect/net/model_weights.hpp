#pragma once
// The networks of a configuration, and their weights and checkpoints on disk (internal to the LibTorch component).
#include <filesystem>

#include <torch/torch.h>

#include "mlidar/detect/detect_config.hpp"
#include "mlidar/detect/net/networks.hpp"

namespace mlidar::detect::net {

BevNet make_stage1(const DetectConfig& config);
Refiner make_stage2();

/// A module's weights, written atomically.
void save_weights(torch::nn::Module& module, const std::filesystem::path& path);
/// InputError naming the file when it is missing or its tensors do not fit the module (another configuration).
void load_weights(torch::nn::Module& module, const std::filesystem::path& path);

/// A checkpoint: the module, its optimizer's state and the steps done, written atomically.
void save_checkpoint(torch::nn::Module& module, torch::optim::Optimizer& optimizer, long step, const std::filesystem::path& path);
/// Restores what save_checkpoint wrote; returns the steps done. InputError naming the file when it does not fit.
long load_checkpoint(torch::nn::Module& module, torch::optim::Optimizer& optimizer, const std::filesystem::path& path);

}  // namespace mlidar::detect::net
