#pragma once
// The frames a detector trains on and runs on (thesis 6.6.1): a dataset folder (`simulate detection`, `perturb`, or
// any dataset.yaml with extrinsics) read through io::FrameSource, each LiDAR's points moved into the base frame by
// its extrinsic, with tr(Xi) of every point (eq 6.7) under the perturbation prior of the extrinsic used, and the
// frame's boxes from groundtruth/label_2/NNNNNN.txt (base frame).
//   - a clean dataset: the extrinsics of dataset.yaml, the prior at alpha 0 (tr(Xi) = 3 sigma_z^2 for every point);
//   - a `perturb` copy: its perturbed extrinsics, the prior at its alpha (groundtruth/perturbation.json) for every
//     LiDAR but the reference;
//   - `alpha` > 0 asked for: each frame's extrinsics drawn anew from the dataset's (eq 6.1-6.2, every component
//     bounded at its sigma, 6.6.1.3) with a seed of its own, the prior at that alpha (Fig 6.5's trials);
//   - online calibration asked for (the "(OC)" rows): each LiDAR's extrinsic of the frame, as above, refined against
//     the reference's scan first (online_extrinsics.hpp).
// Augmentation (6.6.1.5-6.6.1.6): a flip about the x axis, a turn about z, a shift and a scale applied to points and
// boxes alike.
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "mlidar/calib/pair_refine.hpp"
#include "mlidar/core/se3.hpp"
#include "mlidar/detect/detect_config.hpp"
#include "mlidar/io/detection_labels.hpp"
#include "mlidar/io/frame_source.hpp"

namespace mlidar::detect {

/// One LiDAR's points of a frame in the base frame.
struct LidarPoints {
  std::vector<Vec3> points;
  std::vector<float> intensity;     ///< one per point (0 where the cloud has none)
  std::vector<double> uncertainty;  ///< tr(Xi) of each point, m^2 (eq 6.7)
};

/// How one LiDAR's points of a frame were placed in the base frame.
struct LidarPlacement {
  SE3 T_base_lidar_given;      ///< the dataset's extrinsic, or its perturbation drawn for the frame
  SE3 T_base_lidar;            ///< the one the points were moved by: the given one, or online calibration's
  bool refine_ran = false;     ///< online calibration registered this LiDAR in this frame
  calib::PairVerdict refine_verdict = calib::PairVerdict::kNotConverged;  ///< when it ran
};

struct DetectionFrame {
  std::size_t index = 0;
  std::string id;                      ///< "000042": the label and prediction file's stem
  std::vector<LidarPoints> lidars;     ///< dataset order; empty points where a LiDAR has no scan
  std::vector<LidarPlacement> placements;  ///< one per LiDAR, in the order of `lidars`
  std::vector<io::LabelledBox> labels; ///< every class; empty without labels
};

/// The frame with only the LiDARs at `indices` (in that order).
DetectionFrame select_lidars(DetectionFrame frame, const std::vector<std::size_t>& indices);

/// Points of several LiDARs of a frame together (input fusion; stage 2's cloud).
LidarPoints merge_lidars(const DetectionFrame& frame);

class DetectionDataset {
 public:
  /// `need_labels`: InputError naming groundtruth/label_2 when the dataset has none (training needs them).
  /// InputError naming dataset.yaml for a LiDAR without an extrinsic.
  static DetectionDataset open(const std::filesystem::path& folder, bool need_labels);

  std::size_t frames() const { return source_.frames(); }
  const std::vector<std::string>& lidar_names() const { return names_; }
  /// The index of the LiDAR that defines the base frame (never perturbed).
  std::size_t reference() const { return reference_; }
  /// The alpha the dataset's own extrinsics were perturbed at (0 for a clean dataset).
  double dataset_alpha() const { return dataset_alpha_; }
  bool has_labels() const { return has_labels_; }
  const std::filesystem::path& folder() const { return folder_; }

  /// The extrinsics of dataset.yaml (the truth the `alpha` perturbations are drawn about).
  const std::vector<SE3>& dataset_extrinsics() const { return T_base_lidar_; }

  /// Frame k (see the header comment). `alpha` > 0 on a dataset that is itself perturbed is a UsageError.
  /// `online_calibration`: refine every LiDAR's extrinsic against the reference's scan of the frame with it.
  DetectionFrame read(std::size_t k, double alpha = 0.0, std::uint64_t seed = 0,
                      const calib::PairRefineConfig* online_calibration = nullptr) const;

 private:
  DetectionDataset(std::filesystem::path folder, io::FrameSource source) : folder_(std::move(folder)), source_(std::move(source)) {}
  std::filesystem::path folder_;
  io::FrameSource source_;
  std::vector<std::string> names_;
  std::vector<SE3> T_base_lidar_;
  std::size_t reference_ = 0;
  double dataset_alpha_ = 0.0;
  bool has_labels_ = false;
};

/// One draw of 6.6.1.5's augmentation, applied as p' = s Rz(yaw) F p + t (F flips y when `flip_y`).
struct Augmentation {
  bool flip_y = false;
  double yaw = 0.0;
  Vec3 translation = Vec3::Zero();
  double scale = 1.0;
};
/// With probability config.share an augmentation drawn from `config` (scale only `with_scale`), else the identity.
Augmentation draw_augmentation(const AugmentConfig& config, bool with_scale, std::mt19937_64& rng);
Vec3 augment_point(const Augmentation& augmentation, const Vec3& point);
io::Box3D augment_box(const Augmentation& augmentation, const io::Box3D& box);
/// The frame's points and labels augmented alike.
void augment_frame(const Augmentation& augmentation, DetectionFrame& frame);

/// SplitMix64 of `seed` and a stream index: independent seeds per frame (perturbations) or per step (training).
std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream);

/// The boxes of one class.
std::vector<io::Box3D> boxes_of_class(std::span<const io::LabelledBox> labels, io::ObjectClass object_class);

}  // namespace mlidar::detect
