// MLOD's networks on the CPU (issue 23: `detect run` <= 200 ms a frame for 3 LiDARs on 2 threads): stage 1 on one
// simulated lyft street frame (three LiDARs, default detect.yaml: 102.4 m x 102.4 m at 0.4 m pillars) for each
// fusion, BEV grids included, and stage 2 on 50 proposals of 128 points. The weights are the initial ones: the time
// does not depend on them. Threads: LibTorch's, set by --threads=N after the benchmark flags (default 2).
#include <cstdlib>
#include <cstring>

#include <benchmark/benchmark.h>

#include "mlidar/core/heap_settings.hpp"
#include "mlidar/detect/detection_frames.hpp"
#include "mlidar/detect/net/model_weights.hpp"
#include "mlidar/detect/net/stage1.hpp"
#include "mlidar/detect/net/stage2.hpp"
#include "mlidar/sim/detection_dataset.hpp"
#include "mlidar/sim/rig.hpp"

namespace {

using namespace mlidar;
namespace fs = std::filesystem;

const detect::DetectionFrame& street_frame() {
  static const detect::DetectionFrame frame = [] {
    const fs::path folder = fs::temp_directory_path() / "mlidar_bench_mlod";
    fs::remove_all(folder);
    sim::DetectionSpec spec;
    spec.rig = sim::load_rig("lyft");
    spec.frames = 1;
    sim::write_detection_dataset(spec, folder);
    detect::DetectionFrame read = detect::DetectionDataset::open(folder, true).read(0);
    fs::remove_all(folder);
    return read;
  }();
  return frame;
}

void stage1(benchmark::State& state, detect::Fusion fusion) {
  const detect::DetectConfig config;
  detect::net::BevNet net = detect::net::make_stage1(config);
  net->eval();
  const std::vector<double> temperatures(3, 1.0);
  const detect::DetectionFrame& frame = street_frame();
  for (auto _ : state) benchmark::DoNotOptimize(detect::net::stage1_proposals(net, frame, fusion, config, temperatures, 0.3));
  state.counters["points"] = static_cast<double>(detect::merge_lidars(frame).points.size());
}
void BM_Stage1Input(benchmark::State& state) { stage1(state, detect::Fusion::kInput); }
void BM_Stage1Feature(benchmark::State& state) { stage1(state, detect::Fusion::kFeature); }
void BM_Stage1Result(benchmark::State& state) { stage1(state, detect::Fusion::kResult); }
BENCHMARK(BM_Stage1Input)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage1Feature)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Stage1Result)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Stage2FiftyProposals(benchmark::State& state) {
  const detect::DetectConfig config;
  detect::net::Refiner refiner = detect::net::make_stage2();
  refiner->eval();
  const detect::DetectionFrame& frame = street_frame();
  const detect::LidarPoints cloud = detect::merge_lidars(frame);
  std::vector<detect::net::Proposal> proposals;
  for (std::size_t k = 0; proposals.size() < 50; ++k) {
    const io::LabelledBox& label = frame.labels[k % frame.labels.size()];
    proposals.push_back({label.box, 0.5, 0.0});
  }
  torch::NoGradGuard no_grad;
  for (auto _ : state) {
    const detect::net::Stage2Input input = detect::net::stage2_input(cloud, proposals, config);
    benchmark::DoNotOptimize(detect::net::refine(refiner->forward(input.points, input.proposals), proposals, config));
  }
}
BENCHMARK(BM_Stage2FiftyProposals)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  int threads = 2;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--threads=", 10) == 0) threads = std::atoi(argv[i] + 10);
    else argv[kept++] = argv[i];
  }
  argc = kept;
  torch::set_num_threads(threads);
  keep_large_buffers_in_the_heap();  // as the CLI runs
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
