// `mlidar eval detections`: KITTI-style AP of 3D detections in the base frame (definitions in
// src/mlidar/eval/detection_ap.hpp, label files in src/mlidar/io/detection_labels.hpp, JSON keys in
// src/mlidar/eval/detection_report.hpp). Folder layout, frame pairing and option parsing live here.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "apps/mlidar/commands.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/eval/detection_ap.hpp"
#include "mlidar/eval/detection_report.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/detection_labels.hpp"
#include "mlidar/io/text_fields.hpp"
#include "mlidar/report/svg_chart.hpp"

namespace mlidar::cli {
namespace {

namespace fs = std::filesystem;

struct DetectionsOptions {
  std::string gt;
  std::string pred;
  std::string classes = "car,pedestrian,cyclist";
  std::string iou;  ///< CLASS=T,... overriding the strict thresholds
  std::string json_out;
  std::string plot_out;
};

/// Where a side's label files are: DIR/label_2, DIR/groundtruth/label_2 (a `simulate detection` dataset) or DIR.
struct LabelFolder {
  fs::path labels;  ///< the *.txt files
  fs::path root;    ///< the folder holding label_2 (and, for ground truth, labels/*.json); DIR when it holds them
};

LabelFolder label_folder(const fs::path& dir, const std::string& option) {
  if (!fs::is_directory(dir)) throw InputError(dir.string(), option, "not a folder");
  for (const fs::path& root : {dir, dir / "groundtruth"}) {
    if (fs::is_directory(root / "label_2")) return {root / "label_2", root};
  }
  return {dir, dir};
}

/// The *.txt files of `folder` by frame id (the file stem), sorted.
std::vector<fs::path> label_files(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && entry.path().extension() == ".txt") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// InputError naming the first frame that only one side has.
void check_same_frames(const std::vector<fs::path>& gt, const std::vector<fs::path>& pred, const fs::path& gt_folder,
                       const fs::path& pred_folder) {
  for (std::size_t i = 0; i < std::max(gt.size(), pred.size()); ++i) {
    const bool gt_left = i < gt.size() && (i >= pred.size() || gt[i].stem() < pred[i].stem());
    const bool pred_left = i < pred.size() && (i >= gt.size() || pred[i].stem() < gt[i].stem());
    if (gt_left) {
      throw InputError(pred_folder.string(), "frame " + gt[i].stem().string(),
                       "no prediction file for ground-truth frame " + gt[i].stem().string() +
                           " (every frame needs one, empty when nothing was detected)");
    }
    if (pred_left) {
      throw InputError(gt_folder.string(), "frame " + pred[i].stem().string(),
                       "prediction file " + pred[i].filename().string() + " has no ground-truth frame");
    }
  }
}

/// The points on each ground-truth box from DIR/labels/ID.json; empty when DIR/labels does not exist.
std::vector<int> points_of_boxes(const fs::path& gt_root, const std::string& id, const std::vector<io::LabelledBox>& boxes) {
  const fs::path folder = gt_root / "labels";
  if (!fs::is_directory(folder)) return {};
  const fs::path file = folder / (id + ".json");
  const std::vector<io::LabelledObjectInfo> objects = io::read_labelled_objects(file);
  if (objects.size() != boxes.size()) {
    throw InputError(file.string(), "objects",
                     "holds " + std::to_string(objects.size()) + " objects, the frame's label file " + std::to_string(boxes.size()) +
                         " (the same objects in the same order)");
  }
  std::vector<int> points;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    if (objects[k].object_class != boxes[k].object_class) {
      throw InputError(file.string(), "objects[" + std::to_string(k) + "].class",
                       "is " + io::object_class_name(objects[k].object_class) + ", line " + std::to_string(boxes[k].line) +
                           " of the label file " + io::object_class_name(boxes[k].object_class));
    }
    points.push_back(objects[k].points_total);
  }
  return points;
}

std::vector<eval::DetectionFrame> read_frames(const DetectionsOptions& options) {
  const LabelFolder gt = label_folder(options.gt, "--gt");
  const fs::path& gt_folder = gt.labels;
  const fs::path pred_folder = label_folder(options.pred, "--pred").labels;
  const std::vector<fs::path> gt_files = label_files(gt_folder);
  const std::vector<fs::path> pred_files = label_files(pred_folder);
  if (gt_files.empty()) throw InputError(gt_folder.string(), "--gt", "no label file (*.txt) in the folder");
  check_same_frames(gt_files, pred_files, gt_folder, pred_folder);
  std::vector<eval::DetectionFrame> frames;
  frames.reserve(gt_files.size());
  for (std::size_t i = 0; i < gt_files.size(); ++i) {
    eval::DetectionFrame& frame = frames.emplace_back();
    frame.id = gt_files[i].stem().string();
    frame.ground_truth = io::read_detection_labels(gt_files[i], io::ScoreRule::kOptional);
    frame.points_total = points_of_boxes(gt.root, frame.id, frame.ground_truth);
    frame.predictions = io::read_detection_labels(pred_files[i], io::ScoreRule::kRequired);
  }
  return frames;
}

io::ObjectClass class_option(std::string_view name, const std::string& option) {
  const auto found = io::object_class_from_name(io::trim(name));
  if (!found) throw UsageError(option + ": unknown class '" + std::string(name) + "' (known: " + io::known_object_classes() + ")");
  return *found;
}

/// --classes and --iou into the evaluation's configuration.
eval::DetectionEvalConfig eval_config(const DetectionsOptions& options) {
  eval::DetectionEvalConfig config;
  config.classes.clear();
  for (std::string_view name : io::split_tokens(options.classes, ',')) config.classes.push_back(class_option(name, "--classes"));
  for (std::string_view item : io::split_tokens(options.iou, ',')) {
    const std::size_t equals = item.find('=');
    if (equals == std::string_view::npos) throw UsageError("--iou: expected CLASS=THRESHOLD, found '" + std::string(item) + "'");
    const io::ObjectClass object_class = class_option(item.substr(0, equals), "--iou");
    try {
      config.thresholds[static_cast<int>(object_class)].strict = io::parse_finite(item.substr(equals + 1), "--iou", std::string(item));
    } catch (const InputError& e) {
      throw UsageError(std::string("--iou: ") + e.what());
    }
  }
  config.validate();
  return config;
}

/// 3D PR curves of one class at one IoU level: a series per difficulty.
report::Chart pr_chart(const eval::ClassResult& result, eval::IouLevel level) {
  const eval::ThresholdResult& t = result.levels[static_cast<int>(level)];
  std::ostringstream title;
  title << io::object_class_name(result.object_class) << ", 3D IoU >= " << report::short_number(t.iou);
  report::Chart chart;
  chart.title = title.str();
  chart.x_label = "recall";
  chart.y_label = "precision";
  chart.width = 480;
  chart.height = 320;
  const char* colours[] = {"#1b9e77", "#d95f02", "#7570b3"};
  for (const eval::DifficultyResult& d : t.difficulties) {
    report::Series series;
    series.label = eval::difficulty_name(d.difficulty);
    series.colour = colours[static_cast<int>(d.difficulty)];
    for (const eval::PrPoint& p : d.box_3d.curve) {
      series.x.push_back(p.recall);
      series.y.push_back(p.precision);
    }
    if (!series.x.empty()) chart.series.push_back(std::move(series));
  }
  // Fixed axes [0, 1] through two invisible corner points.
  chart.series.push_back({.label = "", .colour = "none", .x = {0.0, 1.0}, .y = {0.0, 1.0}, .dots = false});
  return chart;
}

/// A stand-alone SVG: per class a row of two charts (strict and loose IoU).
std::string pr_plot_svg(const eval::DetectionEvalResult& result) {
  constexpr double kWidth = 480, kHeight = 320;
  std::ostringstream body;
  double y = 0;
  for (const eval::ClassResult& c : result.classes) {
    for (eval::IouLevel level : eval::kIouLevels) {
      body << "<g transform=\"translate(" << (level == eval::IouLevel::kStrict ? 0 : kWidth) << ',' << y << ")\">\n"
           << report::render_svg(pr_chart(c, level)) << "</g>\n";
    }
    y += kHeight;
  }
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << 2 * kWidth << "\" height=\"" << y << "\" viewBox=\"0 0 " << 2 * kWidth
      << ' ' << y << "\">\n"
      << body.str() << "</svg>\n";
  return svg.str();
}

int run_detections(const DetectionsOptions& options) {
  const eval::DetectionEvalConfig config = eval_config(options);
  if (!options.json_out.empty()) io::check_output_file(options.json_out, "--json");
  if (!options.plot_out.empty()) io::check_output_file(options.plot_out, "--plot");
  const std::vector<eval::DetectionFrame> frames = read_frames(options);
  const eval::DetectionEvalResult result = eval::evaluate_detections(frames, config);
  std::cout << eval::format_table(result);
  if (!options.json_out.empty()) {
    const nlohmann::json json = eval::to_json(result);
    io::write_atomically(options.json_out, [&](std::ostream& out) { out << json.dump(2) << '\n'; });
  }
  if (!options.plot_out.empty()) {
    const std::string svg = pr_plot_svg(result);
    io::write_atomically(options.plot_out, [&](std::ostream& out) { out << svg; });
  }
  return 0;
}

}  // namespace

Command add_eval_detections(CLI::App& eval_app) {
  auto options = std::make_shared<DetectionsOptions>();
  CLI::App* sub = eval_app.add_subcommand("detections", "KITTI-style AP (3D and BEV, R40 and R11) of 3D detections in the base frame");
  sub->add_option("--gt", options->gt,
                  "Ground truth: DIR/label_2/*.txt, DIR/groundtruth/label_2/*.txt (a simulate detection dataset) or DIR/*.txt, base-frame "
                  "label_2 lines; labels/*.json beside label_2 gives the points per object")
      ->required();
  sub->add_option("--pred", options->pred, "Predictions: DIR/*.txt (or DIR/label_2/*.txt), label_2 lines with a score, one file per frame")
      ->required();
  sub->add_option("--classes", options->classes, "Classes to evaluate, comma-separated")->capture_default_str();
  sub->add_option("--iou", options->iou, "Strict IoU thresholds per class, e.g. car=0.7,pedestrian=0.5 (default car 0.7, others 0.5)");
  sub->add_option("--json", options->json_out, "Write the APs as JSON to this file");
  sub->add_option("--plot", options->plot_out, "Write the 3D precision/recall curves as SVG to this file");
  return {sub, [options] { return run_detections(*options); }};
}

}  // namespace mlidar::cli
