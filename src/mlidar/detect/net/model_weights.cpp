#include "mlidar/detect/net/model_weights.hpp"

#include <sstream>

#include "mlidar/core/error.hpp"
#include "mlidar/detect/bev_grid.hpp"
#include "mlidar/detect/net/stage2.hpp"
#include "mlidar/io/atomic_file.hpp"

namespace mlidar::detect::net {
namespace fs = std::filesystem;

namespace {

void write_archive(torch::serialize::OutputArchive& archive, const fs::path& path) {
  std::ostringstream bytes;
  archive.save_to(bytes);
  io::write_atomically(path, [&](std::ostream& out) { out << bytes.str(); });
}

[[noreturn]] void unfit(const fs::path& path, const std::exception& e) {
  std::string why = e.what();
  if (const auto end = why.find('\n'); end != std::string::npos) why.resize(end);  // LibTorch appends a C++ backtrace
  throw InputError(path.string(), path.filename().string(),
                   "cannot be read into this configuration's network (" + why + "): it was written for another configuration or version");
}

}  // namespace

BevNet make_stage1(const DetectConfig& config) {
  return BevNet(static_cast<int>(kBevChannels), config.channels, static_cast<int>(config.anchors.yaws.size()));
}

Refiner make_stage2() { return Refiner(kPointFeatures, kProposalFeatures); }

void save_weights(torch::nn::Module& module, const fs::path& path) {
  torch::serialize::OutputArchive archive;
  module.save(archive);
  write_archive(archive, path);
}

void load_weights(torch::nn::Module& module, const fs::path& path) {
  if (!fs::exists(path)) throw InputError(path.string(), path.filename().string(), "missing from the model folder");
  try {
    torch::serialize::InputArchive archive;
    archive.load_from(path.string());
    module.load(archive);
  } catch (const std::exception& e) {  // c10::Error, or TorchScript's reading errors
    unfit(path, e);
  }
}

void save_checkpoint(torch::nn::Module& module, torch::optim::Optimizer& optimizer, long step, const fs::path& path) {
  torch::serialize::OutputArchive archive, weights, state;
  module.save(weights);
  optimizer.save(state);
  archive.write("model", weights);
  archive.write("optimizer", state);
  archive.write("step", torch::tensor(static_cast<std::int64_t>(step)));
  write_archive(archive, path);
}

long load_checkpoint(torch::nn::Module& module, torch::optim::Optimizer& optimizer, const fs::path& path) {
  try {
    torch::serialize::InputArchive archive, weights, state;
    archive.load_from(path.string());
    archive.read("model", weights);
    archive.read("optimizer", state);
    module.load(weights);
    optimizer.load(state);
    torch::Tensor step;
    archive.read("step", step);
    return static_cast<long>(step.item<std::int64_t>());
  } catch (const std::exception& e) {  // c10::Error, or TorchScript's reading errors
    unfit(path, e);
  }
}

}  // namespace mlidar::detect::net
