#pragma once
// detect.yaml: everything `mlidar detect train` and `detect run` need besides the data (thesis 6.5-6.6.1). Every key
// is optional; the defaults are the thesis's where it gives them (positives IoU 0.6 / negatives 0.45, eta = 2,
// lambda = 0.005, the 2 m margin, the 1 : 1.5 clean : uncertain ratio, 6.6.1.5's augmentation) and SECOND's
// otherwise (anchor size, focal loss alpha 0.25 / gamma 2). config/detect.yaml lists every key with its default and
// meaning. Unknown or repeated keys and out-of-range values are InputErrors naming the file and the key.
// A model folder keeps the effective configuration (format_detect_config) and its fingerprint, so `detect run` uses
// exactly what training used.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "mlidar/detect/anchor_targets.hpp"
#include "mlidar/detect/bev_grid.hpp"
#include "mlidar/io/detection_labels.hpp"

namespace mlidar::detect {

struct Stage1TrainConfig {
  int epochs = 20;                 ///< passes over the training frames
  double learning_rate = 2e-3;     ///< Adam's, decayed by a cosine to a tenth at the end
  double weight_decay = 1e-4;
  double focal_alpha = 0.25;       ///< focal loss (Lin et al. 2017), SECOND's values
  double focal_gamma = 2.0;
  double regression_weight = 2.0;  ///< smooth-L1 of the anchor residuals, per positive
  double direction_weight = 0.2;   ///< the heading's half-turn classifier
  int checkpoint_every = 200;      ///< steps between checkpoints (rounded up to a multiple of the log's 10 steps)
  /// Share of stage 1's training frames read with perturbed extrinsics (at stage2.alphas), the same 1 : 1.5 clean :
  /// perturbed as stage 2's. The thesis trains stage 1 on clean frames only (0); measured here, such a stage 1 loses
  /// 80 % of its AP at alpha 0.04 and stage 2 cannot give back the cars it never proposed (docs/benchmarks.md, MLOD).
  double uncertain_share = 0.6;
};

/// 6.6.1.5-6.6.1.6's augmentation: a share of the samples is flipped about the x axis (y -> -y), moved and turned
/// about z; stage 2's samples are also scaled.
struct AugmentConfig {
  double share = 0.3;
  bool flip_y = true;
  double translation_x_m = 0.5, translation_y_m = 0.5, translation_z_m = 0.3;
  double rotation_deg = 5.0;
  double scale_min = 0.95, scale_max = 1.05;  ///< stage 2 only
};

struct InferenceConfig {
  double score_threshold = 0.3;  ///< stage 1's probability below which an anchor is no proposal
  int pre_nms = 200;             ///< best anchors decoded before NMS
  double nms_iou = 0.2;          ///< 3D IoU above which the weaker of two boxes is dropped
  int max_detections = 100;
};

struct Stage2Config {
  int epochs = 10;
  double learning_rate = 1e-3;
  double margin_m = 2.0;       ///< 6.5.2: each proposal grown by 2 m on every side
  int points = 128;            ///< points per proposal fed to PointNet (sampled or repeated)
  double positive_iou = 0.6;   ///< 6.6.1.6
  double negative_iou = 0.45;
  double eta = 2.0;            ///< eq 6.17
  double lambda = 0.005;       ///< eq 6.17
  double uncertain_share = 0.6;  ///< 6.6.1.6's 1 : 1.5 clean : uncertain samples
  std::vector<double> alphas = {0.02, 0.04, 0.06, 0.08, 0.1};  ///< injected perturbation levels (6.6.1.3)
  int proposals = 32;          ///< stage-1 proposals per training frame
  int jittered_truths = 4;     ///< extra proposals per true box, moved by up to a quarter of its size (positives)
};

struct DetectConfig {
  io::ObjectClass object_class = io::ObjectClass::kCar;
  std::uint64_t seed = 1;
  int threads = 2;  ///< LibTorch's intra-op threads
  BevGridConfig grid{-51.2, 51.2, -51.2, 51.2, -3.0, 3.0, 0.4};
  AnchorConfig anchors;
  int channels = 32;  ///< the BEV backbone's width (its deeper half has twice as many)
  Stage1TrainConfig stage1;
  AugmentConfig augment;
  InferenceConfig inference;
  Stage2Config stage2;
  double validation_share = 0.1;  ///< result fusion: the training frames' tail kept out to fit each LiDAR's temperature
};

/// `config` with the keys of `yaml_text` applied; `source` names the file in errors.
DetectConfig apply_detect_config(const std::string& yaml_text, const std::string& source, DetectConfig config = {});
DetectConfig read_detect_config(const std::filesystem::path& path);
/// A model or training folder's own detect.yaml: as read_detect_config, except that a key the folder's writer did not
/// know yet has the value that writer used (stage1.uncertain_share: 0), so older folders keep their fingerprint.
DetectConfig read_model_detect_config(const std::filesystem::path& path);
/// Every key with its value (exact numbers; stage1.uncertain_share only when not 0): what a model folder keeps;
/// read_model_detect_config reads it back the same.
std::string format_detect_config(const DetectConfig& config);
/// A short hex digest of format_detect_config (FNV-1a 64) with `threads` left out: two configurations that train
/// different models differ.
std::string detect_config_fingerprint(const DetectConfig& config);

}  // namespace mlidar::detect
