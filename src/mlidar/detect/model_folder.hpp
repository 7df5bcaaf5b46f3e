#pragma once
// A detector's model folder (`mlidar detect train --out MODEL_DIR`, `detect run --model MODEL_DIR`):
//   model.json        {"format": "mlidar-detect-model", "version", "class", "fusion", "lidar", "lidars",
//                      "stages": [1] or [1, 2], "config_fingerprint", "temperatures": {LIDAR: T} (result fusion),
//                      "stage1": {"steps", "final_loss", "seconds"}, "stage2": {...}}; written last, atomically, each
//                      time a stage ends: a folder without it holds no finished model
//   detect.yaml       the effective configuration (every key), the one `detect run` uses
//   stage1.pt stage2.pt   the networks' weights (LibTorch archives)
//   training.json     what is being trained and how far (the resumable state's index)
//   checkpoint_stage1.pt checkpoint_stage2.pt   weights and optimizer state at the last checkpoint
//   train_log.jsonl   one JSON object per logged step: {"stage", "step", "epoch", "loss", terms..., "lr", "seconds"}
//   loss.svg          the training loss against the step, one line per stage
// The folder is checked before use: another format or version, a configuration that is not the one the weights were
// trained with (its fingerprint), unknown fusion: InputError (exit 3) with the reason.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "mlidar/detect/detect_config.hpp"

namespace mlidar::detect {

inline constexpr const char* kModelFormat = "mlidar-detect-model";
inline constexpr int kModelVersion = 1;

/// Where several LiDARs meet (thesis 6.5.1): none (one LiDAR alone), input (clouds merged), feature (per-LiDAR BEV
/// features fused by max, eq 6.10), result (per-LiDAR boxes fused by NMS, eq 6.11).
enum class Fusion : std::uint8_t { kNone, kInput, kFeature, kResult };
std::string fusion_name(Fusion fusion);
/// UsageError naming `option` for another name.
Fusion fusion_from_name(const std::string& name, const std::string& option);

struct StageRecord {
  long steps = 0;
  double final_loss = 0.0;
  double seconds = 0.0;
};

struct ModelInfo {
  io::ObjectClass object_class = io::ObjectClass::kCar;
  Fusion fusion = Fusion::kInput;
  std::string lidar;                ///< the one LiDAR of fusion none
  std::vector<std::string> lidars;  ///< the LiDARs the detector reads, dataset order
  std::vector<int> stages;          ///< trained stages
  std::string config_fingerprint;
  std::map<std::string, double> temperatures;  ///< result fusion: each LiDAR's score temperature
  std::map<int, StageRecord> records;          ///< per trained stage
};

/// Reads and checks MODEL_DIR/model.json and MODEL_DIR/detect.yaml; returns both.
struct ModelFolder {
  ModelInfo info;
  DetectConfig config;
};
ModelFolder read_model_folder(const std::filesystem::path& folder);
/// model.json, atomically.
void write_model_info(const std::filesystem::path& folder, const ModelInfo& info);

}  // namespace mlidar::detect
