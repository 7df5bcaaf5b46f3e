#pragma once
// The model folder while a detector trains (model_folder.hpp has the layout): what --out may be, training.json, and
// train_log.jsonl with its plot. No LibTorch here.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "mlidar/detect/net/detector.hpp"

namespace mlidar::detect::net {

struct StageProgress {
  long steps_done = 0;  ///< at the last checkpoint
  long steps = 0;       ///< of the whole stage
  bool done = false;
};

/// training.json.
struct TrainingRecord {
  std::string fingerprint;
  Fusion fusion = Fusion::kInput;
  std::string lidar;
  std::vector<std::string> lidars;
  std::string data;
  std::map<int, StageProgress> stages;
  std::map<std::string, double> temperatures;
};

/// Checks request.out against the rules of `detect train` and returns the training to go on with: a new one (the folder
/// created, detect.yaml and training.json written) or the one there (--resume, or --stage 2 after a finished stage 1).
/// UsageError for a folder with other files, a training there without --resume, --resume with nothing to resume,
/// --stage 2 without a trained stage 1; InputError for a training of another configuration, fusion, LiDAR or version.
TrainingRecord open_training_folder(const TrainRequest& request, const std::vector<std::string>& lidars);
void write_training_record(const std::filesystem::path& folder, const TrainingRecord& record);
/// model.json from the record: the stages done, the configuration's class and fingerprint.
void write_model_for(const std::filesystem::path& folder, const TrainingRecord& record, const DetectConfig& config,
                     const std::map<int, StageRecord>& records);

/// One line of train_log.jsonl.
struct LogLine {
  int stage = 1;
  long step = 0;  ///< steps done
  long epoch = 0;
  double loss = 0.0;
  std::map<std::string, double> terms;
  double learning_rate = 0.0;
  double seconds = 0.0;  ///< since this run of the stage began
};

/// train_log.jsonl: `keep_until` drops a stage's lines past a checkpoint (a resumed run logs them again);
/// `append` adds a line (flushed); `write_plot` draws loss.svg from the file.
class TrainingLog {
 public:
  explicit TrainingLog(std::filesystem::path folder) : folder_(std::move(folder)) {}
  void keep_until(int stage, long step) const;
  void append(const LogLine& line) const;
  void write_plot() const;

 private:
  std::filesystem::path folder_;
};

}  // namespace mlidar::detect::net
