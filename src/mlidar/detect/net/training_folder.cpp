#include "mlidar/detect/net/training_folder.hpp"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::detect::net {
namespace fs = std::filesystem;

namespace {

constexpr const char* kTrainingFormat = "mlidar-detect-training";

TrainingRecord parse_record(const fs::path& path) {
  const std::string source = path.string();
  const nlohmann::json json = nlohmann::json::parse(io::read_file_text(path), nullptr, false);
  if (json.is_discarded() || !json.is_object() || json.value("format", "") != kTrainingFormat) {
    throw InputError(source, "format", "not a training written by `mlidar detect train`");
  }
  if (json.value("version", 0) != kModelVersion) {
    throw InputError(source, "version", "a training of model format version " + std::to_string(json.value("version", 0)) +
                                            ", this mlidar trains version " + std::to_string(kModelVersion) + " (start a new --out)");
  }
  try {
    TrainingRecord record;
    record.fingerprint = json.at("config_fingerprint").get<std::string>();
    record.fusion = fusion_from_name(json.at("fusion").get<std::string>(), "fusion");
    record.lidar = json.at("lidar").get<std::string>();
    record.lidars = json.at("lidars").get<std::vector<std::string>>();
    record.data = json.at("data").get<std::string>();
    record.temperatures = json.value("temperatures", std::map<std::string, double>{});
    for (const int stage : {1, 2}) {
      const std::string key = "stage" + std::to_string(stage);
      if (!json.contains(key)) continue;
      const nlohmann::json& s = json[key];
      record.stages[stage] = {s.at("steps_done").get<long>(), s.at("steps").get<long>(), s.at("done").get<bool>()};
    }
    return record;
  } catch (const std::exception& e) {
    throw InputError(source, "(document)", std::string("unreadable training record: ") + e.what());
  }
}

bool inside(const fs::path& path, const fs::path& folder) {
  const fs::path p = fs::weakly_canonical(path), f = fs::weakly_canonical(folder);
  auto [end, _] = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return end == f.end();
}

std::string stage_state(const TrainingRecord& record) {
  std::string text;
  for (const auto& [stage, progress] : record.stages) {
    text += (text.empty() ? "" : ", ") + std::string("stage ") + std::to_string(stage) + " " +
            (progress.done ? "done" : "at step " + std::to_string(progress.steps_done) + " of " + std::to_string(progress.steps));
  }
  return text.empty() ? "nothing trained yet" : text;
}

}  // namespace

void write_training_record(const fs::path& folder, const TrainingRecord& record) {
  nlohmann::json json = {{"format", kTrainingFormat},    {"version", kModelVersion}, {"config_fingerprint", record.fingerprint},
                         {"fusion", fusion_name(record.fusion)}, {"lidar", record.lidar},  {"lidars", record.lidars},
                         {"data", record.data},          {"temperatures", record.temperatures}};
  for (const auto& [stage, progress] : record.stages) {
    json["stage" + std::to_string(stage)] = {{"steps_done", progress.steps_done}, {"steps", progress.steps}, {"done", progress.done}};
  }
  io::write_atomically(folder / "training.json", [&](std::ostream& out) { out << json.dump(2) << '\n'; });
}

TrainingRecord open_training_folder(const TrainRequest& request, const std::vector<std::string>& lidars) {
  const fs::path& out = request.out;
  const std::string fingerprint = detect_config_fingerprint(request.config);
  if (inside(out, request.data) || inside(request.data, out)) {
    throw UsageError("--out " + out.string() + ": may not be the dataset, inside it or hold it (" + request.data.string() + ")");
  }
  if (fs::exists(out) && !fs::is_directory(out)) throw UsageError("--out " + out.string() + ": is a file, not a folder");
  const bool empty = !fs::exists(out) || fs::is_empty(out);
  if (empty) {
    if (request.resume) throw UsageError("--resume: " + out.string() + " holds no training to resume");
    if (request.stage == 2) throw UsageError("--stage 2: " + out.string() + " holds no trained stage 1 (train stage 1 there first)");
    fs::create_directories(out);
    TrainingRecord record{fingerprint, request.fusion, request.lidar, lidars, fs::absolute(request.data).string(), {}, {}};
    io::write_atomically(out / "detect.yaml", [&](std::ostream& stream) { stream << format_detect_config(request.config); });
    write_training_record(out, record);
    return record;
  }
  const fs::path path = out / "training.json";
  if (!fs::exists(path)) {
    throw UsageError("--out " + out.string() + ": holds files that are no detector training (never overwritten); choose a new or empty folder");
  }
  TrainingRecord record = parse_record(path);
  if (record.fingerprint != fingerprint) {
    throw InputError(path.string(), "config_fingerprint",
                     "this folder trains another configuration (" + record.fingerprint + ", --config gives " + fingerprint +
                         "); resume with the folder's own detect.yaml, or train into a new --out");
  }
  if (record.fusion != request.fusion || record.lidar != request.lidar) {
    throw InputError(path.string(), "fusion", "this folder trains fusion " + fusion_name(record.fusion) +
                                                  (record.lidar.empty() ? "" : " of LiDAR " + record.lidar) + ", not " + fusion_name(request.fusion) +
                                                  (request.lidar.empty() ? "" : " of LiDAR " + request.lidar));
  }
  const bool stage1_done = record.stages.contains(1) && record.stages.at(1).done;
  const bool fresh_stage2 = request.stage == 2 && stage1_done && !record.stages.contains(2);
  if (request.stage == 2 && !stage1_done) throw UsageError("--stage 2: " + out.string() + " holds no finished stage 1 (" + stage_state(record) + ")");
  if (!request.resume && !fresh_stage2) {
    throw UsageError("--out " + out.string() + ": holds a training (" + stage_state(record) +
                     "); continue it with --resume, add stage 2 with --stage 2, or choose another --out");
  }
  return record;
}

void write_model_for(const fs::path& folder, const TrainingRecord& record, const DetectConfig& config, const std::map<int, StageRecord>& records) {
  ModelInfo info;
  info.object_class = config.object_class;
  info.fusion = record.fusion;
  info.lidar = record.lidar;
  info.lidars = record.lidars;
  info.config_fingerprint = record.fingerprint;
  info.temperatures = record.temperatures;
  for (const auto& [stage, progress] : record.stages) {
    if (progress.done) info.stages.push_back(stage);
  }
  info.records = records;
  write_model_info(folder, info);
}

void TrainingLog::keep_until(int stage, long step) const {
  const fs::path path = folder_ / "train_log.jsonl";
  if (!fs::exists(path)) return;
  std::istringstream lines(io::read_file_text(path));
  std::string kept, line;
  while (std::getline(lines, line)) {
    const nlohmann::json json = nlohmann::json::parse(line, nullptr, false);
    if (json.is_discarded()) continue;  // a line cut short by a kill
    if (json.value("stage", 0) == stage && json.value("step", 0L) > step) continue;
    kept += line + '\n';
  }
  io::write_atomically(path, [&](std::ostream& out) { out << kept; });
}

void TrainingLog::append(const LogLine& line) const {
  nlohmann::json json = {{"stage", line.stage}, {"step", line.step}, {"epoch", line.epoch}, {"loss", line.loss},
                         {"lr", line.learning_rate}, {"seconds", line.seconds}};
  for (const auto& [name, value] : line.terms) json[name] = value;
  std::ofstream out(folder_ / "train_log.jsonl", std::ios::app);
  out << json.dump() << '\n';
  out.flush();
  if (!out) throw OutputError((folder_ / "train_log.jsonl").string() + ": cannot append to the training log");
}

void TrainingLog::write_plot() const {
  const fs::path path = folder_ / "train_log.jsonl";
  report::Chart chart;
  chart.title = "Training loss";
  chart.x_label = "step";
  chart.y_label = "loss";
  chart.log_y = true;
  report::Series stages[2] = {{"stage 1", "#1f77b4", {}, {}, false}, {"stage 2 (eq 6.17)", "#d62728", {}, {}, false}};
  if (fs::exists(path)) {
    std::istringstream lines(io::read_file_text(path));
    std::string line;
    while (std::getline(lines, line)) {
      const nlohmann::json json = nlohmann::json::parse(line, nullptr, false);
      if (json.is_discarded()) continue;
      const int stage = json.value("stage", 0);
      if (stage != 1 && stage != 2) continue;
      stages[stage - 1].x.push_back(json.value("step", 0.0));
      stages[stage - 1].y.push_back(json.value("loss", 0.0));
    }
  }
  for (const report::Series& series : stages) {
    if (!series.x.empty()) chart.series.push_back(series);
  }
  std::string svg = report::render_svg(chart);
  if (svg.rfind("<svg ", 0) == 0) svg.insert(5, "xmlns=\"http://www.w3.org/2000/svg\" ");  // a file of its own, not inline HTML
  io::write_atomically(folder_ / "loss.svg", [&](std::ostream& out) { out << svg; });
}

}  // namespace mlidar::detect::net
