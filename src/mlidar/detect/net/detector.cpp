#include "mlidar/detect/net/detector.hpp"

#include <chrono>

#include "mlidar/core/error.hpp"
#include "mlidar/detect/net/model_weights.hpp"
#include "mlidar/detect/net/stage2.hpp"

namespace mlidar::detect {
namespace fs = std::filesystem;

struct Detector::State {
  ModelFolder folder;
  net::BevNet stage1{nullptr};
  net::Refiner stage2{nullptr};
  std::vector<double> temperatures;  ///< per model LiDAR (result fusion)
};

Detector::Detector(std::unique_ptr<State> state) : state_(std::move(state)) {}
Detector::~Detector() = default;
Detector::Detector(Detector&&) noexcept = default;
Detector& Detector::operator=(Detector&&) noexcept = default;

Detector Detector::load(const fs::path& folder, int stages, int threads) {
  auto state = std::make_unique<State>();
  state->folder = read_model_folder(folder);
  const ModelInfo& info = state->folder.info;
  const DetectConfig& config = state->folder.config;
  torch::set_num_threads(threads > 0 ? threads : config.threads);
  state->stage1 = net::make_stage1(config);
  net::load_weights(*state->stage1, folder / "stage1.pt");
  state->stage1->eval();
  const bool has_stage2 = std::find(info.stages.begin(), info.stages.end(), 2) != info.stages.end();
  if (stages == 2 && !has_stage2) throw UsageError("--stage 2: the model in " + folder.string() + " has no trained stage 2");
  if (has_stage2 && stages != 1) {
    state->stage2 = net::make_stage2();
    net::load_weights(*state->stage2, folder / "stage2.pt");
    state->stage2->eval();
  }
  for (const std::string& name : info.lidars) {
    const auto it = info.temperatures.find(name);
    state->temperatures.push_back(it == info.temperatures.end() ? 1.0 : it->second);
  }
  return Detector(std::move(state));
}

const ModelInfo& Detector::info() const { return state_->folder.info; }
const DetectConfig& Detector::config() const { return state_->folder.config; }
bool Detector::refines() const { return !state_->stage2.is_empty(); }

FrameDetections Detector::detect(const DetectionFrame& frame) const {
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point from) { return std::chrono::duration<double, std::milli>(Clock::now() - from).count(); };
  const DetectConfig& config = state_->folder.config;
  torch::NoGradGuard no_grad;
  FrameDetections out;
  const Clock::time_point start = Clock::now();
  const std::vector<net::Proposal> proposals =
      net::stage1_proposals(state_->stage1, frame, info().fusion, config, state_->temperatures, config.inference.score_threshold);
  out.stage1_ms = ms(start);
  if (!refines() || proposals.empty()) {
    for (const net::Proposal& proposal : proposals) out.boxes.push_back({config.object_class, proposal.box, proposal.score, 0});
    return out;
  }
  const Clock::time_point refine_start = Clock::now();
  const net::Stage2Input input = net::stage2_input(merge_lidars(frame), proposals, config);
  out.boxes = net::refine(state_->stage2->forward(input.points, input.proposals), proposals, config);
  out.stage2_ms = ms(refine_start);
  return out;
}

std::vector<std::size_t> model_lidar_indices(const ModelInfo& info, const std::vector<std::string>& dataset_lidars, const std::string& source) {
  std::vector<std::size_t> indices;
  for (const std::string& name : info.lidars) {
    const auto it = std::find(dataset_lidars.begin(), dataset_lidars.end(), name);
    if (it == dataset_lidars.end()) {
      throw InputError(source, "lidars", "the model reads LiDAR '" + name + "', which this dataset does not have (a model is trained for one rig)");
    }
    indices.push_back(static_cast<std::size_t>(it - dataset_lidars.begin()));
  }
  return indices;
}

}  // namespace mlidar::detect
