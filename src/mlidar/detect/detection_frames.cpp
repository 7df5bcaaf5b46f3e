#include "mlidar/detect/detection_frames.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include "mlidar/core/error.hpp"
#include "mlidar/core/extrinsic_perturbation.hpp"
#include "mlidar/detect/online_extrinsics.hpp"
#include "mlidar/io/file_bytes.hpp"

namespace mlidar::detect {
namespace fs = std::filesystem;

namespace {

std::string frame_id(std::size_t k) {
  char id[32];
  std::snprintf(id, sizeof(id), "%06zu", k);
  return id;
}

/// groundtruth/perturbation.json's alpha, 0 when the dataset has none.
double perturbation_alpha(const fs::path& folder) {
  const fs::path path = folder / "groundtruth" / "perturbation.json";
  if (!fs::exists(path)) return 0.0;
  const nlohmann::json json = nlohmann::json::parse(io::read_file_text(path), nullptr, false);
  if (json.is_discarded() || !json.contains("alpha") || !json["alpha"].is_number() || json["alpha"].get<double>() < 0.0) {
    throw InputError(path.string(), "alpha", "expected a number >= 0 (the file `mlidar perturb` writes)");
  }
  return json["alpha"].get<double>();
}

/// The scan's points in the base frame by pose.T, with tr(Xi) (eq 6.7) under pose's covariance when `uncertain`
/// (else 3 sigma_z^2, the clean value).
LidarPoints lidar_points(const Scan& scan, const UncertainPose& pose, const Mat3& Z, bool uncertain) {
  LidarPoints out;
  out.points.reserve(scan.size());
  out.intensity.reserve(scan.size());
  out.uncertainty.reserve(scan.size());
  const double clean = Z.trace();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const Vec3 p = scan.points[i].cast<double>();
    if (!p.allFinite()) continue;
    out.points.push_back(pose.T * p);
    out.intensity.push_back(scan.has_intensity() ? scan.intensity[i] : 0.0f);
    out.uncertainty.push_back(uncertain ? point_covariance(pose, p, Z).trace() : clean);  // eq 6.7
  }
  return out;
}

}  // namespace

DetectionFrame select_lidars(DetectionFrame frame, const std::vector<std::size_t>& indices) {
  std::vector<LidarPoints> selected;
  std::vector<LidarPlacement> placements;
  for (const std::size_t j : indices) {
    selected.push_back(std::move(frame.lidars.at(j)));
    if (j < frame.placements.size()) placements.push_back(frame.placements[j]);
  }
  frame.lidars = std::move(selected);
  frame.placements = std::move(placements);
  return frame;
}

LidarPoints merge_lidars(const DetectionFrame& frame) {
  LidarPoints merged;
  for (const LidarPoints& lidar : frame.lidars) {
    merged.points.insert(merged.points.end(), lidar.points.begin(), lidar.points.end());
    merged.intensity.insert(merged.intensity.end(), lidar.intensity.begin(), lidar.intensity.end());
    merged.uncertainty.insert(merged.uncertainty.end(), lidar.uncertainty.begin(), lidar.uncertainty.end());
  }
  return merged;
}

DetectionDataset DetectionDataset::open(const fs::path& folder, bool need_labels) {
  if (!fs::is_directory(folder)) throw InputError(folder.string(), "--dataset", "not a folder (a dataset written by `mlidar simulate detection`)");
  DetectionDataset dataset(folder, io::FrameSource::dataset(folder));
  const auto& lidars = dataset.source_.lidars();
  for (std::size_t j = 0; j < lidars.size(); ++j) {
    if (!lidars[j].initial_extrinsic) {
      throw InputError((folder / "dataset.yaml").string(), "lidars[" + std::to_string(j) + "].initial_extrinsic",
                       "LiDAR '" + lidars[j].name + "' has no extrinsic; a detector needs every LiDAR in the base frame (calibrate first)");
    }
    dataset.names_.push_back(lidars[j].name);
    dataset.T_base_lidar_.push_back(*lidars[j].initial_extrinsic);
  }
  dataset.reference_ = dataset.source_.reference_index().value_or(0);
  dataset.dataset_alpha_ = perturbation_alpha(folder);
  const fs::path labels = folder / "groundtruth" / "label_2";
  dataset.has_labels_ = fs::is_directory(labels);
  if (need_labels && !dataset.has_labels_) {
    throw InputError(labels.string(), "groundtruth/label_2", "the dataset has no labels; training needs a labelled dataset (`mlidar simulate detection`)");
  }
  if (dataset.frames() == 0) throw InputError(folder.string(), "times.txt", "the dataset has no frames");
  return dataset;
}

DetectionFrame DetectionDataset::read(std::size_t k, double alpha, std::uint64_t seed,
                                      const calib::PairRefineConfig* online_calibration) const {
  if (alpha > 0.0 && dataset_alpha_ > 0.0) {
    throw UsageError(folder_.string() + " is already perturbed (alpha " + std::to_string(dataset_alpha_) +
                     "); give --alpha with its clean source dataset, or leave --alpha out");
  }
  DetectionFrame frame;
  frame.index = k;
  frame.id = frame_id(k);
  const io::SourceFrame source = source_.read(k);
  std::mt19937_64 rng(mix_seed(seed, k));
  const std::optional<Scan>& reference = source.scans[reference_];
  const std::size_t count = source.scans.size();
  // The given extrinsics first, in LiDAR order (one random stream per frame) ...
  std::vector<PerturbationPrior> priors(count);
  frame.placements.resize(count);
  for (std::size_t j = 0; j < count; ++j) {
    priors[j].alpha = j == reference_ ? 0.0 : (alpha > 0.0 ? alpha : dataset_alpha_);
    frame.placements[j].T_base_lidar_given =
        alpha > 0.0 && j != reference_ ? sample_perturbed_extrinsic(T_base_lidar_[j], priors[j], rng) : T_base_lidar_[j];
  }
  // ... then online calibration's registrations, independent of each other, in parallel ...
  std::vector<std::optional<RefinedExtrinsic>> refined(count);
  if (online_calibration != nullptr && reference) {
    tbb::parallel_for(std::size_t{0}, count, [&](std::size_t j) {
      if (j == reference_ || !source.scans[j]) return;
      refined[j] = refine_extrinsic_online(*reference, T_base_lidar_[reference_], *source.scans[j], frame.placements[j].T_base_lidar_given,
                                           *online_calibration);
    });
  }
  // ... and each LiDAR's points in the base frame with the extrinsic in use.
  for (std::size_t j = 0; j < count; ++j) {
    LidarPlacement& placement = frame.placements[j];
    UncertainPose pose = uncertain_extrinsic(placement.T_base_lidar_given, priors[j]);
    bool uncertain = priors[j].alpha > 0.0;
    if (refined[j]) {
      placement.refine_ran = true;
      placement.refine_verdict = refined[j]->registration.verdict;
      if (refined[j]->trusted()) {
        pose = refined[j]->uncertain_extrinsic;
        uncertain = true;
      }
    }
    placement.T_base_lidar = pose.T;
    const std::optional<Scan>& scan = source.scans[j];
    frame.lidars.push_back(scan ? lidar_points(*scan, pose, prior_point_noise(priors[j]), uncertain) : LidarPoints{});
  }
  if (has_labels_) {
    const fs::path path = folder_ / "groundtruth" / "label_2" / (frame.id + ".txt");
    if (!fs::exists(path)) throw InputError(path.string(), "frame " + frame.id, "no label file for this frame (every frame needs one, empty when it has no object)");
    frame.labels = io::read_detection_labels(path, io::ScoreRule::kOptional);
  }
  return frame;
}

Augmentation draw_augmentation(const AugmentConfig& config, bool with_scale, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto symmetric = [&](double half) { return half * (2.0 * unit(rng) - 1.0); };
  Augmentation augmentation;
  if (unit(rng) >= config.share) return augmentation;
  augmentation.flip_y = config.flip_y && unit(rng) < 0.5;
  augmentation.yaw = symmetric(config.rotation_deg * std::numbers::pi / 180.0);
  augmentation.translation = {symmetric(config.translation_x_m), symmetric(config.translation_y_m), symmetric(config.translation_z_m)};
  if (with_scale) augmentation.scale = config.scale_min + (config.scale_max - config.scale_min) * unit(rng);
  return augmentation;
}

Vec3 augment_point(const Augmentation& a, const Vec3& point) {
  const Vec3 flipped(point.x(), a.flip_y ? -point.y() : point.y(), point.z());
  const double c = std::cos(a.yaw), s = std::sin(a.yaw);
  return a.scale * Vec3(c * flipped.x() - s * flipped.y(), s * flipped.x() + c * flipped.y(), flipped.z()) + a.translation;
}

io::Box3D augment_box(const Augmentation& a, const io::Box3D& box) {
  io::Box3D out = box;
  out.center_bottom = augment_point(a, box.center_bottom);  // the bottom stays the bottom: z is only scaled and shifted
  out.yaw = (a.flip_y ? -box.yaw : box.yaw) + a.yaw;
  out.yaw = std::remainder(out.yaw, 2.0 * std::numbers::pi);
  out.length *= a.scale, out.width *= a.scale, out.height *= a.scale;
  return out;
}

void augment_frame(const Augmentation& augmentation, DetectionFrame& frame) {
  for (LidarPoints& lidar : frame.lidars) {
    for (Vec3& p : lidar.points) p = augment_point(augmentation, p);
  }
  for (io::LabelledBox& label : frame.labels) label.box = augment_box(augmentation, label.box);
}

std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::vector<io::Box3D> boxes_of_class(std::span<const io::LabelledBox> labels, io::ObjectClass object_class) {
  std::vector<io::Box3D> boxes;
  for (const io::LabelledBox& label : labels) {
    if (label.object_class == object_class) boxes.push_back(label.box);
  }
  return boxes;
}

}  // namespace mlidar::detect
