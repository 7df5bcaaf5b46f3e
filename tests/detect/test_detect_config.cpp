// detect.yaml: the documented example is the defaults, strict keys, the model folder's fingerprint and checks.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/detect/detect_config.hpp"
#include "mlidar/detect/model_folder.hpp"
#include "test_support.hpp"

namespace mlidar::detect {
namespace {

namespace fs = std::filesystem;

std::string failure(const std::string& yaml) {
  try {
    apply_detect_config(yaml, "detect.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(DetectConfig, TheDocumentedExampleHoldsEveryKeyAtItsDefault) {
  const fs::path example = fs::path(MLIDAR_SOURCE_DIR) / "config" / "detect.yaml";
  const DetectConfig read = read_detect_config(example);
  EXPECT_EQ(format_detect_config(read), format_detect_config(DetectConfig{}));
  // Every key format_detect_config writes is in the example (a key added without documenting it fails here).
  const std::string text = test::read_text(example);
  std::istringstream lines(format_detect_config(DetectConfig{}));
  for (std::string line; std::getline(lines, line);) {
    const std::string key = line.substr(0, line.find(':') + 1);
    EXPECT_NE(text.find(key), std::string::npos) << key << " is not documented in config/detect.yaml";
  }
}

TEST(DetectConfig, ThesisValuesAreTheDefaults) {
  const DetectConfig config;
  EXPECT_EQ(config.stage2.eta, 2.0);        // eq 6.17
  EXPECT_EQ(config.stage2.lambda, 0.005);   // eq 6.17
  EXPECT_EQ(config.stage2.margin_m, 2.0);   // 6.5.2
  EXPECT_EQ(config.stage2.positive_iou, 0.6);
  EXPECT_EQ(config.stage2.negative_iou, 0.45);
  EXPECT_NEAR(config.stage2.uncertain_share / (1.0 - config.stage2.uncertain_share), 1.5, 1e-12);  // 1 : 1.5
  EXPECT_EQ(config.augment.translation_x_m, 0.5);  // 6.6.1.5
  EXPECT_EQ(config.augment.translation_z_m, 0.3);
  EXPECT_EQ(config.augment.rotation_deg, 5.0);
  EXPECT_EQ(config.augment.share, 0.3);
}

TEST(DetectConfig, AppliesKeysAndRoundTripsThroughItsOwnText) {
  const DetectConfig config = apply_detect_config("class: Pedestrian\nstage2:\n  alphas: [0.04]\n  eta: 3\ngrid: {cell: 0.2}\n", "x.yaml");
  EXPECT_EQ(config.object_class, io::ObjectClass::kPedestrian);
  EXPECT_EQ(config.stage2.alphas, std::vector<double>{0.04});
  EXPECT_EQ(config.stage2.eta, 3.0);
  EXPECT_EQ(config.grid.cell, 0.2);
  const DetectConfig again = apply_detect_config(format_detect_config(config), "again.yaml");
  EXPECT_EQ(format_detect_config(again), format_detect_config(config));
  EXPECT_EQ(detect_config_fingerprint(again), detect_config_fingerprint(config));
}

TEST(DetectConfig, FingerprintChangesWithTheModelNotWithTheThreads) {
  DetectConfig a, b;
  b.threads = 7;
  EXPECT_EQ(detect_config_fingerprint(a), detect_config_fingerprint(b));
  b.stage2.lambda = 0.006;
  EXPECT_NE(detect_config_fingerprint(a), detect_config_fingerprint(b));
}

TEST(DetectConfig, BadKeysAndValuesNameTheKey) {
  EXPECT_NE(failure("stage1:\n  epoch: 3\n").find("stage1.epoch: unknown key"), std::string::npos);
  EXPECT_NE(failure("seed: 1\nseed: 2\n").find("seed"), std::string::npos);
  EXPECT_NE(failure("stage2:\n  eta: -1\n").find("stage2.eta"), std::string::npos);
  EXPECT_NE(failure("class: truck\n").find("unknown class"), std::string::npos);
  EXPECT_NE(failure("grid:\n  x_max: 51.0\n").find("multiple of 4"), std::string::npos);
  EXPECT_NE(failure("stage1:\n  epochs: 2.5\n").find("whole number"), std::string::npos);
  EXPECT_NE(failure("anchors:\n  negative_iou: 0.7\n").find("anchors.negative_iou"), std::string::npos);
  EXPECT_NE(failure("augmentation:\n  flip_y: maybe\n").find("true or false"), std::string::npos);
  EXPECT_EQ(failure(""), "");  // an empty file keeps the defaults
}

ModelInfo two_stage_model(const DetectConfig& config) {
  ModelInfo info;
  info.fusion = Fusion::kFeature;
  info.lidars = {"top", "front_left", "front_right"};
  info.stages = {1, 2};
  info.config_fingerprint = detect_config_fingerprint(config);
  info.records[1] = {100, 0.5, 12.0};
  return info;
}

TEST(ModelFolder, ReadsWhatItWroteAndRefusesAnotherConfigurationOrVersion) {
  const fs::path folder = test::scratch_dir();
  DetectConfig config;
  config.channels = 16;
  {
    std::ofstream(folder / "detect.yaml") << format_detect_config(config);
  }
  write_model_info(folder, two_stage_model(config));
  const ModelFolder read = read_model_folder(folder);
  EXPECT_EQ(read.info.fusion, Fusion::kFeature);
  EXPECT_EQ(read.info.stages, (std::vector<int>{1, 2}));
  EXPECT_EQ(read.config.channels, 16);
  EXPECT_EQ(read.info.records.at(1).steps, 100);
  // Someone edits detect.yaml: the weights were not trained with it.
  {
    DetectConfig edited = config;
    edited.validation_share = 0.2;
    std::ofstream(folder / "detect.yaml") << format_detect_config(edited);
  }
  EXPECT_THROW(
      {
        try {
          read_model_folder(folder);
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("not the one the weights were trained with"), std::string::npos) << e.what();
          throw;
        }
      },
      InputError);
  {
    std::ofstream(folder / "detect.yaml") << format_detect_config(config);
    std::string json = test::read_text(folder / "model.json");
    json.replace(json.find("\"version\": 1"), 12, "\"version\": 9");
    std::ofstream(folder / "model.json") << json;
  }
  try {
    read_model_folder(folder);
    ADD_FAILURE() << "a model of another format version was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("version 9"), std::string::npos) << e.what();
  }
}

// The detect.yaml and fingerprint of a model trained (small protocol run, input fusion) by the version before
// stage1.uncertain_share existed: such folders must still load, with stage 1 known to have seen clean frames only.
constexpr const char* kYamlBeforeStage1Perturbation = R"(class: car
seed: 1
threads: 2
validation_share: 0.1
grid:
  x_min: -51.2
  x_max: 51.2
  y_min: -51.2
  y_max: 51.2
  z_min: -3
  z_max: 3
  cell: 0.4
anchors:
  length: 3.9
  width: 1.6
  height: 1.56
  bottom_z: 0
  stride: 2
  positive_iou: 0.6
  negative_iou: 0.45
network:
  channels: 32
stage1:
  epochs: 8
  learning_rate: 0.002
  weight_decay: 1e-04
  focal_alpha: 0.25
  focal_gamma: 2
  regression_weight: 2
  direction_weight: 0.2
  checkpoint_every: 200
augmentation:
  share: 0.3
  flip_y: true
  translation_m: [0.5, 0.5, 0.3]
  rotation_deg: 5
  scale: [0.95, 1.05]
inference:
  score_threshold: 0.3
  pre_nms: 200
  nms_iou: 0.2
  max_detections: 100
stage2:
  epochs: 3
  learning_rate: 0.001
  margin_m: 2
  points: 128
  positive_iou: 0.6
  negative_iou: 0.45
  eta: 2
  lambda: 0.005
  uncertain_share: 0.6
  alphas: [0.02, 0.04, 0.06, 0.08, 0.1]
  proposals: 32
  jittered_truths: 4
)";

TEST(ModelFolder, AFolderWrittenBeforeStageOnePerturbationStillLoads) {
  const fs::path folder = test::scratch_dir();
  test::write_text(folder / "detect.yaml", kYamlBeforeStage1Perturbation);
  ModelInfo info;
  info.fusion = Fusion::kInput;
  info.lidars = {"top", "front_left", "front_right"};
  info.stages = {1};
  info.config_fingerprint = "3e6a9c876cf4b179";  // that version's model.json
  write_model_info(folder, info);
  const ModelFolder read = read_model_folder(folder);
  EXPECT_EQ(read.config.stage1.uncertain_share, 0.0);
  EXPECT_EQ(read.config.stage1.epochs, 8);
  // The same text as a user's --config means today's default: stage 1 sees perturbed frames, another model.
  const DetectConfig as_user_config = apply_detect_config(kYamlBeforeStage1Perturbation, "detect.yaml");
  EXPECT_EQ(as_user_config.stage1.uncertain_share, 0.6);
  EXPECT_NE(detect_config_fingerprint(as_user_config), info.config_fingerprint);
}

TEST(ModelFolder, AFolderWithoutAModelSaysWhy) {
  const fs::path folder = test::scratch_dir();
  try {
    read_model_folder(folder);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no model.json"), std::string::npos) << e.what();
  }
  std::ofstream(folder / "training.json") << "{}";
  try {
    read_model_folder(folder);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--resume"), std::string::npos) << e.what();
  }
}

TEST(ModelFolder, FusionNames) {
  for (const Fusion fusion : {Fusion::kNone, Fusion::kInput, Fusion::kFeature, Fusion::kResult}) {
    EXPECT_EQ(fusion_from_name(fusion_name(fusion), "--fusion"), fusion);
  }
  EXPECT_THROW(fusion_from_name("early", "--fusion"), UsageError);
}

}  // namespace
}  // namespace mlidar::detect
