#pragma once
// MLOD (thesis 6.5) on LibTorch, behind a header without Torch types: only this component's .cpp files include
// <torch/torch.h>, so nothing else in mlidar compiles against LibTorch.
//
// Stage 1 (6.5.1) is SECOND's detector with its sparse middle layers replaced by a dense bird's-eye-view 2D CNN (sparse
// convolution is not packaged for Debian; on a CPU a dense BEV network at 0.4 m pillars is the realistic equivalent):
// pillar features (detect/bev_grid: SECOND V1.5's mean-of-voxel features) -> a stride-2 block -> a stride-4 block ->
// an up-convolution back to stride 2 -> SECOND's anchor head (two yaws per cell; class, 7 residuals, heading
// direction). Fusion: `input` merges the clouds before the grid; `feature` runs the first block on each LiDAR's grid
// and takes the maximum (eq 6.10) before the rest; `result` runs one network on each LiDAR's grid and fuses the
// boxes by NMS on 3D IoU after temperature scaling (eq 6.11); `none` reads one LiDAR.
// Stage 2 (6.5.2) is a PointNet over each proposal's points grown by the margin, in its canonical frame (eq 6.12-6.13),
// each point with log tr(Xi); it scores the proposal and regresses eq 6.14's residual; loss eq 6.15-6.17.
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mlidar/detect/detection_frames.hpp"
#include "mlidar/detect/model_folder.hpp"

namespace mlidar::detect {

struct TrainRequest {
  std::filesystem::path data;   ///< a labelled dataset (`simulate detection`)
  DetectConfig config;
  Fusion fusion = Fusion::kInput;
  std::string lidar;            ///< fusion none: the LiDAR
  int stage = 0;                ///< 0: stage 1 then stage 2; 1 or 2: that stage alone (2 needs a trained stage 1)
  std::filesystem::path out;    ///< the model folder
  bool resume = false;          ///< continue the training in `out` from its last checkpoint
  long max_steps = 0;           ///< > 0: stop each stage after this many steps (tests, quick looks)
};

struct TrainProgress {
  int stage = 1;
  long step = 0;       ///< steps done
  long steps = 0;      ///< of the stage
  double loss = 0.0;   ///< mean over the last logged steps
  double seconds = 0.0;  ///< of this stage so far, this run
  long first_step = 0;   ///< where this run started (resumed runs): the ETA's rate counts from here
};

/// Trains into request.out (model_folder.hpp). UsageError for an --out that may not be used (a folder with other
/// files; a training there without --resume), InputError for a dataset without labels or a folder of another
/// configuration, fusion or version.
void train_detector(const TrainRequest& request, const std::function<void(const TrainProgress&)>& progress = {});

struct FrameDetections {
  std::vector<io::LabelledBox> boxes;  ///< base frame, scores in (0, 1)
  double stage1_ms = 0.0;              ///< BEV grids and stage 1 (with result fusion's NMS)
  double stage2_ms = 0.0;              ///< proposal points and stage 2 (0 without it)
};

class Detector {
 public:
  /// The model in `folder` (checked: model_folder.hpp); `stages` 1 runs only stage 1 of a two-stage model, 0 all
  /// trained stages. `threads` LibTorch threads (0: the configuration's).
  static Detector load(const std::filesystem::path& folder, int stages = 0, int threads = 0);
  ~Detector();
  Detector(Detector&&) noexcept;
  Detector& operator=(Detector&&) noexcept;

  const ModelInfo& info() const;
  const DetectConfig& config() const;
  bool refines() const;  ///< stage 2 runs
  /// The frame's detections; `frame.lidars` are the model's LiDARs in info().lidars order (select_lidars).
  FrameDetections detect(const DetectionFrame& frame) const;

 private:
  struct State;
  explicit Detector(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

/// Indices in `dataset_lidars` of the model's LiDARs; InputError naming `source` for one the dataset lacks.
std::vector<std::size_t> model_lidar_indices(const ModelInfo& info, const std::vector<std::string>& dataset_lidars, const std::string& source);

}  // namespace mlidar::detect
