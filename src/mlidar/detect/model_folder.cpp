#include "mlidar/detect/model_folder.hpp"

#include <nlohmann/json.hpp>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"

namespace mlidar::detect {
namespace fs = std::filesystem;

std::string fusion_name(Fusion fusion) {
  switch (fusion) {
    case Fusion::kNone: return "none";
    case Fusion::kInput: return "input";
    case Fusion::kFeature: return "feature";
    case Fusion::kResult: return "result";
  }
  return "?";
}

Fusion fusion_from_name(const std::string& name, const std::string& option) {
  for (const Fusion fusion : {Fusion::kNone, Fusion::kInput, Fusion::kFeature, Fusion::kResult}) {
    if (fusion_name(fusion) == name) return fusion;
  }
  throw UsageError(option + ": unknown fusion '" + name + "' (one of none, input, feature, result)");
}

namespace {

template <typename T>
T field(const nlohmann::json& json, const std::string& key, const std::string& source) {
  if (!json.contains(key)) throw InputError(source, key, "missing (the folder was not written by `mlidar detect train`)");
  try {
    return json.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw InputError(source, key, "has the wrong type (the folder was not written by this version of `mlidar detect train`)");
  }
}

ModelInfo parse_model_info(const nlohmann::json& json, const std::string& source) {
  const auto format = field<std::string>(json, "format", source);
  if (format != kModelFormat) throw InputError(source, "format", "'" + format + "' is no mlidar detector model");
  const int version = field<int>(json, "version", source);
  if (version != kModelVersion) {
    throw InputError(source, "version", "model format version " + std::to_string(version) + ", this mlidar reads version " +
                                            std::to_string(kModelVersion) + " (train the model again with this version)");
  }
  ModelInfo info;
  const auto object_class = io::object_class_from_name(field<std::string>(json, "class", source));
  if (!object_class) throw InputError(source, "class", "unknown class (one of " + io::known_object_classes() + ")");
  info.object_class = *object_class;
  try {
    info.fusion = fusion_from_name(field<std::string>(json, "fusion", source), "fusion");
  } catch (const UsageError& e) {
    throw InputError(source, "fusion", e.what());
  }
  info.lidar = field<std::string>(json, "lidar", source);
  info.lidars = field<std::vector<std::string>>(json, "lidars", source);
  info.stages = field<std::vector<int>>(json, "stages", source);
  info.config_fingerprint = field<std::string>(json, "config_fingerprint", source);
  if (json.contains("temperatures")) info.temperatures = field<std::map<std::string, double>>(json, "temperatures", source);
  for (const int stage : info.stages) {
    const std::string key = "stage" + std::to_string(stage);
    if (stage != 1 && stage != 2) throw InputError(source, "stages", "expected stages 1 and 2 only");
    if (json.contains(key)) {
      const nlohmann::json& record = json[key];
      info.records[stage] = {field<long>(record, "steps", source), field<double>(record, "final_loss", source),
                             field<double>(record, "seconds", source)};
    }
  }
  if (info.lidars.empty()) throw InputError(source, "lidars", "no LiDAR: the model reads nothing");
  return info;
}

}  // namespace

ModelFolder read_model_folder(const fs::path& folder) {
  const fs::path model = folder / "model.json";
  if (!fs::is_directory(folder)) throw InputError(folder.string(), "--model", "not a folder (a model folder written by `mlidar detect train`)");
  if (!fs::exists(model)) {
    const std::string why = fs::exists(folder / "training.json") ? "its training has not finished a stage yet (continue it with `mlidar detect train --resume`)"
                                                                 : "no model.json: not a model folder written by `mlidar detect train`";
    throw InputError(model.string(), "model.json", why);
  }
  const nlohmann::json json = nlohmann::json::parse(io::read_file_text(model), nullptr, false);
  if (json.is_discarded() || !json.is_object()) throw InputError(model.string(), "(document)", "not a JSON object");
  ModelFolder out;
  out.info = parse_model_info(json, model.string());
  if (out.info.stages.empty() || out.info.stages.front() != 1) throw InputError(model.string(), "stages", "no trained stage 1");
  const fs::path yaml = folder / "detect.yaml";
  if (!fs::exists(yaml)) throw InputError(yaml.string(), "detect.yaml", "missing: the model's configuration is part of the model folder");
  out.config = read_model_detect_config(yaml);
  const std::string fingerprint = detect_config_fingerprint(out.config);
  if (fingerprint != out.info.config_fingerprint) {
    throw InputError(yaml.string(), "config_fingerprint",
                     "this configuration (" + fingerprint + ") is not the one the weights were trained with (" + out.info.config_fingerprint +
                         "): the folder's detect.yaml was changed or comes from another model");
  }
  return out;
}

void write_model_info(const fs::path& folder, const ModelInfo& info) {
  nlohmann::json json = {{"format", kModelFormat},
                         {"version", kModelVersion},
                         {"class", io::object_class_name(info.object_class)},
                         {"fusion", fusion_name(info.fusion)},
                         {"lidar", info.lidar},
                         {"lidars", info.lidars},
                         {"stages", info.stages},
                         {"config_fingerprint", info.config_fingerprint},
                         {"temperatures", info.temperatures}};
  for (const auto& [stage, record] : info.records) {
    json["stage" + std::to_string(stage)] = {{"steps", record.steps}, {"final_loss", record.final_loss}, {"seconds", record.seconds}};
  }
  io::write_atomically(folder / "model.json", [&](std::ostream& out) { out << json.dump(2) << '\n'; });
}

}  // namespace mlidar::detect
