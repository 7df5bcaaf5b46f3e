#include "mlidar/detect/detect_config.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/text_fields.hpp"
#include "mlidar/io/yaml_fields.hpp"

namespace mlidar::detect {
namespace {

/// Reads the keys of one mapping of detect.yaml; each setter names its key path in errors.
class Section {
 public:
  Section(const io::YamlFields& fields, const YAML::Node& map, std::string path) : fields_(fields), map_(map), path_(std::move(path)) {}

  void number(const std::string& key, double lo, double hi, double& value) const {
    if (map_[key]) value = fields_.number_in(map_[key], name(key), lo, hi);
  }
  template <typename Int>
  void integer(const std::string& key, Int lo, Int hi, Int& value) const {
    if (!map_[key]) return;
    const double number = fields_.number_in(map_[key], name(key), static_cast<double>(lo), static_cast<double>(hi));
    if (number != std::floor(number)) fields_.fail(name(key), "expected a whole number");
    value = static_cast<Int>(number);
  }
  void flag(const std::string& key, bool& value) const {
    if (!map_[key]) return;
    const std::string text = fields_.text(map_[key], name(key));
    if (text != "true" && text != "false") fields_.fail(name(key), "expected true or false, got '" + text + "'");
    value = text == "true";
  }
  std::string name(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const YAML::Node& map() const { return map_; }

 private:
  const io::YamlFields& fields_;
  YAML::Node map_;
  std::string path_;
};

void read_grid(const io::YamlFields& fields, const YAML::Node& map, BevGridConfig& grid) {
  fields.only_keys(map, "grid", {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max", "cell"});
  const Section s(fields, map, "grid");
  s.number("x_min", -500.0, 500.0, grid.x_min);
  s.number("x_max", -500.0, 500.0, grid.x_max);
  s.number("y_min", -500.0, 500.0, grid.y_min);
  s.number("y_max", -500.0, 500.0, grid.y_max);
  s.number("z_min", -50.0, 50.0, grid.z_min);
  s.number("z_max", -50.0, 50.0, grid.z_max);
  s.number("cell", 0.05, 5.0, grid.cell);
  if (grid.x_max <= grid.x_min) fields.fail("grid.x_max", "must exceed grid.x_min");
  if (grid.y_max <= grid.y_min) fields.fail("grid.y_max", "must exceed grid.y_min");
  if (grid.z_max <= grid.z_min) fields.fail("grid.z_max", "must exceed grid.z_min");
}

void read_anchors(const io::YamlFields& fields, const YAML::Node& map, AnchorConfig& anchors) {
  fields.only_keys(map, "anchors", {"length", "width", "height", "bottom_z", "stride", "positive_iou", "negative_iou"});
  const Section s(fields, map, "anchors");
  s.number("length", 0.05, 50.0, anchors.length);
  s.number("width", 0.05, 50.0, anchors.width);
  s.number("height", 0.05, 50.0, anchors.height);
  s.number("bottom_z", -50.0, 50.0, anchors.bottom_z);
  s.integer("stride", 2, 2, anchors.stride);  // the backbone's first block halves the grid
  s.number("positive_iou", 0.0, 1.0, anchors.positive_iou);
  s.number("negative_iou", 0.0, 1.0, anchors.negative_iou);
  if (anchors.negative_iou > anchors.positive_iou) fields.fail("anchors.negative_iou", "must not exceed anchors.positive_iou");
}

void read_stage1(const io::YamlFields& fields, const YAML::Node& map, Stage1TrainConfig& stage1) {
  fields.only_keys(map, "stage1", {"epochs", "learning_rate", "weight_decay", "focal_alpha", "focal_gamma", "regression_weight",
                                   "direction_weight", "checkpoint_every", "uncertain_share"});
  const Section s(fields, map, "stage1");
  s.integer("epochs", 1, 100000, stage1.epochs);
  s.number("learning_rate", 1e-7, 1.0, stage1.learning_rate);
  s.number("weight_decay", 0.0, 1.0, stage1.weight_decay);
  s.number("focal_alpha", 0.0, 1.0, stage1.focal_alpha);
  s.number("focal_gamma", 0.0, 10.0, stage1.focal_gamma);
  s.number("regression_weight", 0.0, 100.0, stage1.regression_weight);
  s.number("direction_weight", 0.0, 100.0, stage1.direction_weight);
  s.integer("checkpoint_every", 1, 1000000, stage1.checkpoint_every);
  s.number("uncertain_share", 0.0, 1.0, stage1.uncertain_share);
}

void read_augment(const io::YamlFields& fields, const YAML::Node& map, AugmentConfig& augment) {
  fields.only_keys(map, "augmentation", {"share", "flip_y", "translation_m", "rotation_deg", "scale"});
  const Section s(fields, map, "augmentation");
  s.number("share", 0.0, 1.0, augment.share);
  s.flag("flip_y", augment.flip_y);
  if (map["translation_m"]) {
    const std::vector<double> t = fields.numbers(map["translation_m"], "augmentation.translation_m", 3);
    for (std::size_t i = 0; i < 3; ++i) {
      if (t[i] < 0.0 || t[i] > 10.0) fields.fail("augmentation.translation_m[" + std::to_string(i) + "]", "expected a value in [0, 10] m");
    }
    augment.translation_x_m = t[0], augment.translation_y_m = t[1], augment.translation_z_m = t[2];
  }
  s.number("rotation_deg", 0.0, 180.0, augment.rotation_deg);
  if (map["scale"]) {
    const std::vector<double> scale = fields.numbers(map["scale"], "augmentation.scale", 2);
    if (scale[0] <= 0.0 || scale[1] < scale[0] || scale[1] > 10.0) fields.fail("augmentation.scale", "expected [lo, hi] with 0 < lo <= hi <= 10");
    augment.scale_min = scale[0], augment.scale_max = scale[1];
  }
}

void read_inference(const io::YamlFields& fields, const YAML::Node& map, InferenceConfig& inference) {
  fields.only_keys(map, "inference", {"score_threshold", "pre_nms", "nms_iou", "max_detections"});
  const Section s(fields, map, "inference");
  s.number("score_threshold", 0.0, 1.0, inference.score_threshold);
  s.integer("pre_nms", 1, 100000, inference.pre_nms);
  s.number("nms_iou", 0.0, 1.0, inference.nms_iou);
  s.integer("max_detections", 1, 100000, inference.max_detections);
}

void read_stage2(const io::YamlFields& fields, const YAML::Node& map, Stage2Config& stage2) {
  fields.only_keys(map, "stage2", {"epochs", "learning_rate", "margin_m", "points", "positive_iou", "negative_iou", "eta", "lambda",
                                   "uncertain_share", "alphas", "proposals", "jittered_truths"});
  const Section s(fields, map, "stage2");
  s.integer("epochs", 1, 100000, stage2.epochs);
  s.number("learning_rate", 1e-7, 1.0, stage2.learning_rate);
  s.number("margin_m", 0.0, 20.0, stage2.margin_m);
  s.integer("points", 8, 4096, stage2.points);
  s.number("positive_iou", 0.0, 1.0, stage2.positive_iou);
  s.number("negative_iou", 0.0, 1.0, stage2.negative_iou);
  if (stage2.negative_iou > stage2.positive_iou) fields.fail("stage2.negative_iou", "must not exceed stage2.positive_iou");
  s.number("eta", 0.0, 1000.0, stage2.eta);
  s.number("lambda", 0.0, 1000.0, stage2.lambda);
  s.number("uncertain_share", 0.0, 1.0, stage2.uncertain_share);
  if (map["alphas"]) {
    stage2.alphas = fields.numbers(map["alphas"], "stage2.alphas", 0);
    for (std::size_t i = 0; i < stage2.alphas.size(); ++i) {
      if (stage2.alphas[i] < 0.0 || stage2.alphas[i] > 1.0) fields.fail("stage2.alphas[" + std::to_string(i) + "]", "expected a value in [0, 1]");
    }
  }
  s.integer("proposals", 1, 10000, stage2.proposals);
  s.integer("jittered_truths", 0, 100, stage2.jittered_truths);
}

void read_root(const io::YamlFields& fields, const YAML::Node& root, DetectConfig& config) {
  fields.only_keys(root, "", {"class", "seed", "threads", "grid", "anchors", "network", "stage1", "augmentation", "inference", "stage2",
                              "validation_share"});
  if (root["class"]) {
    const std::string name = fields.text(root["class"], "class");
    const auto object_class = io::object_class_from_name(name);
    if (!object_class) fields.fail("class", "unknown class '" + name + "' (one of " + io::known_object_classes() + ")");
    config.object_class = *object_class;
  }
  const Section s(fields, root, "");
  s.integer("seed", std::uint64_t{0}, std::uint64_t{1} << 52, config.seed);
  s.integer("threads", 1, 256, config.threads);
  s.number("validation_share", 0.0, 0.9, config.validation_share);
  if (root["grid"]) read_grid(fields, root["grid"], config.grid);
  if (root["anchors"]) read_anchors(fields, root["anchors"], config.anchors);
  if (root["network"]) {
    fields.only_keys(root["network"], "network", {"channels"});
    Section(fields, root["network"], "network").integer("channels", 4, 512, config.channels);
  }
  if (root["stage1"]) read_stage1(fields, root["stage1"], config.stage1);
  if (root["augmentation"]) read_augment(fields, root["augmentation"], config.augment);
  if (root["inference"]) read_inference(fields, root["inference"], config.inference);
  if (root["stage2"]) read_stage2(fields, root["stage2"], config.stage2);
  const double cells_x = (config.grid.x_max - config.grid.x_min) / config.grid.cell;
  const double cells_y = (config.grid.y_max - config.grid.y_min) / config.grid.cell;
  if (cells_x * cells_y > 4e6) fields.fail("grid.cell", "the grid would have more than 4 million pillars (a larger cell or a smaller area)");
  // The backbone halves the head's grid once more and an up-convolution brings it back: whole numbers of cells.
  for (const auto& [cells, key] : {std::pair{cells_x, "grid.x_max"}, std::pair{cells_y, "grid.y_max"}}) {
    if (std::abs(cells - std::round(cells)) > 1e-6 || static_cast<long>(std::round(cells)) % 4 != 0) {
      fields.fail(key, "the extent divided by grid.cell must be a whole multiple of 4 cells (got " + io::exact_number(cells) + ")");
    }
  }
}

std::string list(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + io::exact_number(values[i]);
  return text + "]";
}

}  // namespace

DetectConfig apply_detect_config(const std::string& yaml_text, const std::string& source, DetectConfig config) {
  const io::YamlFields fields(source, "detect.yaml");
  const YAML::Node root = fields.load(yaml_text);
  if (root && !root.IsNull()) read_root(fields, root, config);
  return config;
}

DetectConfig read_detect_config(const std::filesystem::path& path) {
  return apply_detect_config(io::read_file_text(path), path.string());
}

DetectConfig read_model_detect_config(const std::filesystem::path& path) {
  DetectConfig before_the_key;
  before_the_key.stage1.uncertain_share = 0.0;
  return apply_detect_config(io::read_file_text(path), path.string(), before_the_key);
}

std::string format_detect_config(const DetectConfig& c) {
  const auto n = [](double value) { return io::exact_number(value); };
  std::ostringstream out;
  out << "class: " << io::object_class_name(c.object_class) << "\nseed: " << c.seed << "\nthreads: " << c.threads
      << "\nvalidation_share: " << n(c.validation_share) << "\ngrid:\n  x_min: " << n(c.grid.x_min) << "\n  x_max: " << n(c.grid.x_max)
      << "\n  y_min: " << n(c.grid.y_min) << "\n  y_max: " << n(c.grid.y_max) << "\n  z_min: " << n(c.grid.z_min)
      << "\n  z_max: " << n(c.grid.z_max) << "\n  cell: " << n(c.grid.cell) << "\nanchors:\n  length: " << n(c.anchors.length)
      << "\n  width: " << n(c.anchors.width) << "\n  height: " << n(c.anchors.height) << "\n  bottom_z: " << n(c.anchors.bottom_z)
      << "\n  stride: " << c.anchors.stride << "\n  positive_iou: " << n(c.anchors.positive_iou)
      << "\n  negative_iou: " << n(c.anchors.negative_iou) << "\nnetwork:\n  channels: " << c.channels
      << "\nstage1:\n  epochs: " << c.stage1.epochs << "\n  learning_rate: " << n(c.stage1.learning_rate)
      << "\n  weight_decay: " << n(c.stage1.weight_decay) << "\n  focal_alpha: " << n(c.stage1.focal_alpha)
      << "\n  focal_gamma: " << n(c.stage1.focal_gamma) << "\n  regression_weight: " << n(c.stage1.regression_weight)
      << "\n  direction_weight: " << n(c.stage1.direction_weight) << "\n  checkpoint_every: " << c.stage1.checkpoint_every
      // Left out at 0, what folders written before the key meant: their fingerprints stay what they were.
      << (c.stage1.uncertain_share > 0.0 ? "\n  uncertain_share: " + n(c.stage1.uncertain_share) : std::string())
      << "\naugmentation:\n  share: " << n(c.augment.share) << "\n  flip_y: " << (c.augment.flip_y ? "true" : "false")
      << "\n  translation_m: " << list({c.augment.translation_x_m, c.augment.translation_y_m, c.augment.translation_z_m})
      << "\n  rotation_deg: " << n(c.augment.rotation_deg) << "\n  scale: " << list({c.augment.scale_min, c.augment.scale_max})
      << "\ninference:\n  score_threshold: " << n(c.inference.score_threshold) << "\n  pre_nms: " << c.inference.pre_nms
      << "\n  nms_iou: " << n(c.inference.nms_iou) << "\n  max_detections: " << c.inference.max_detections
      << "\nstage2:\n  epochs: " << c.stage2.epochs << "\n  learning_rate: " << n(c.stage2.learning_rate)
      << "\n  margin_m: " << n(c.stage2.margin_m) << "\n  points: " << c.stage2.points << "\n  positive_iou: " << n(c.stage2.positive_iou)
      << "\n  negative_iou: " << n(c.stage2.negative_iou) << "\n  eta: " << n(c.stage2.eta) << "\n  lambda: " << n(c.stage2.lambda)
      << "\n  uncertain_share: " << n(c.stage2.uncertain_share) << "\n  alphas: " << list(c.stage2.alphas)
      << "\n  proposals: " << c.stage2.proposals << "\n  jittered_truths: " << c.stage2.jittered_truths << "\n";
  return out.str();
}

std::string detect_config_fingerprint(const DetectConfig& config) {
  DetectConfig model = config;
  model.threads = 1;  // how many threads train a model is no part of it
  std::uint64_t hash = 0xcbf29ce484222325ULL;  // FNV-1a 64
  for (const char c : format_detect_config(model)) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ULL;
  }
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace mlidar::detect
