#include "mlidar/pipelines/perturb_dataset.hpp"

#include <cstdio>
#include <cstring>
#include <random>
#include <system_error>

#include <nlohmann/json.hpp>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/core/so3.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/io/pcd.hpp"

namespace mlidar::pipelines {
namespace {

namespace fs = std::filesystem;

fs::path dataset_folder(const fs::path& dataset) { return fs::is_directory(dataset) ? dataset : dataset.parent_path(); }

/// The extrinsics the perturbation starts from: ground truth when the dataset has it, else dataset.yaml's.
std::vector<PerturbedLidar> true_extrinsics(const io::Dataset& dataset, const fs::path& folder) {
  std::optional<io::Extrinsics> truth;
  if (dataset.groundtruth.extrinsics) {
    const fs::path file = folder / *dataset.groundtruth.extrinsics;
    truth = io::read_extrinsics(file);
    if (truth->base != dataset.base)
      throw InputError(file.string(), "base",
                       "is '" + truth->base + "' but dataset.yaml's base is '" + dataset.base +
                           "' (give the ground truth relative to the dataset's base)");
  }
  const std::string reference = dataset.reference_lidar.empty() ? dataset.base : dataset.reference_lidar;
  std::vector<PerturbedLidar> lidars;
  for (const auto& lidar : dataset.lidars) {
    const io::LidarExtrinsic* known = truth ? truth->find(lidar.name) : nullptr;
    if (known == nullptr && !lidar.initial_extrinsic)
      throw InputError((folder / "dataset.yaml").string(), "lidars." + lidar.name + ".initial_extrinsic",
                       "missing, and no ground-truth extrinsic for this LiDAR either: there is no extrinsic to perturb "
                       "(give initial_extrinsic or groundtruth/extrinsics.yaml)");
    const SE3 T = known != nullptr ? known->T_base_lidar : *lidar.initial_extrinsic;
    lidars.push_back({lidar.name, T, T, lidar.name != reference});
  }
  return lidars;
}

/// Paths dataset.yaml names outside its folder stay pointing at the original (absolute); the rest are copied.
fs::path kept_path(const fs::path& path, const fs::path& folder) {
  if (path.is_absolute()) return path;
  const fs::path relative = path.lexically_normal();
  if (!relative.empty() && *relative.begin() == "..") return fs::absolute(folder / relative).lexically_normal();
  return path;
}

/// Copies (or hard-links) every file of the dataset folder but what the copy writes anew.
void copy_dataset_files(const fs::path& folder, const fs::path& out, bool link) {
  const fs::path out_canonical = fs::weakly_canonical(out);
  for (auto it = fs::recursive_directory_iterator(folder); it != fs::recursive_directory_iterator(); ++it) {
    const fs::path relative = it->path().lexically_relative(folder);
    const std::string top = relative.begin()->string();
    const bool rewritten = relative == "dataset.yaml" || relative == "run.json" || relative == "extrinsics_perturbed.yaml" ||
                           relative == fs::path("groundtruth") / "perturbation.json" || top == "fused";
    if (rewritten || fs::weakly_canonical(it->path()) == out_canonical) {
      if (it->is_directory()) it.disable_recursion_pending();
      continue;
    }
    if (it->is_directory()) {
      fs::create_directories(out / relative);
      continue;
    }
    std::error_code linked;
    if (link) fs::create_hard_link(it->path(), out / relative, linked);
    if (!link || linked) fs::copy_file(it->path(), out / relative, fs::copy_options::overwrite_existing);
  }
}

nlohmann::json perturbation_json(const PerturbSpec& spec, const std::vector<PerturbedLidar>& lidars) {
  nlohmann::json per_lidar = nlohmann::json::object();
  for (const auto& lidar : lidars) {
    const Vec3 rho = lidar.T_base_lidar_perturbed.translation() - lidar.T_base_lidar_true.translation();
    const Vec3 phi = so3_log(lidar.T_base_lidar_perturbed.rotation() * lidar.T_base_lidar_true.rotation().conjugate());
    per_lidar[lidar.name] = {{"perturbed", lidar.perturbed},
                             {"rho_m", {rho.x(), rho.y(), rho.z()}},
                             {"phi_rad", {phi.x(), phi.y(), phi.z()}},
                             {"translation_error_m", rho.norm()},
                             {"rotation_error_deg", rad_to_deg(phi.norm())}};
  }
  return {{"alpha", spec.prior.alpha},
          {"seed", spec.seed},
          {"model", "t = rho + t_true, R = Exp(phi) R_true (thesis eq 6.1-6.2), each component ~ N(0, sigma^2) bounded at sigma"},
          {"sigma_translation_m", spec.prior.scaled_translation_sigma()},
          {"sigma_rotation_rad", spec.prior.scaled_rotation_sigma()},
          {"sigma_point_m", spec.prior.point_sigma_m},
          {"lidars", per_lidar}};
}

io::Extrinsics perturbed_extrinsics(const std::string& base, const PerturbSpec& spec, const std::vector<PerturbedLidar>& lidars) {
  io::Extrinsics extrinsics;
  extrinsics.base = base;
  for (const auto& lidar : lidars) {
    const Mat6 covariance =
        lidar.perturbed ? perturbation_covariance_in_file_tangent(spec.prior, lidar.T_base_lidar_perturbed) : Mat6::Zero().eval();
    extrinsics.lidars.push_back({lidar.name, lidar.T_base_lidar_perturbed, covariance});
  }
  return extrinsics;
}

/// One frame's points of every LiDAR in the base frame, with tr(Xi) per point (eq 6.7) under the prior.
io::PointTable fused_cloud(const io::SourceFrame& frame, const std::vector<PerturbedLidar>& lidars, const PerturbSpec& spec) {
  Scan fused;
  std::vector<std::uint8_t> lidar_index;
  std::vector<float> uncertainty;
  PerturbationPrior exact = spec.prior;
  exact.alpha = 0.0;
  for (std::size_t j = 0; j < frame.scans.size(); ++j) {
    if (!frame.scans[j]) continue;
    const Scan& scan = *frame.scans[j];
    const SE3& T = lidars[j].T_base_lidar_perturbed;
    const PerturbationPrior& prior = lidars[j].perturbed ? spec.prior : exact;
    const UncertainPose pose = uncertain_extrinsic(T, prior);
    const Mat3 Z = prior_point_noise(prior);
    for (std::size_t i = 0; i < scan.size(); ++i) {
      const Vec3 p = scan.points[i].cast<double>();
      fused.points.push_back((T * p).cast<float>());
      fused.intensity.push_back(scan.has_intensity() ? scan.intensity[i] : 0.0f);
      lidar_index.push_back(static_cast<std::uint8_t>(j));
      uncertainty.push_back(static_cast<float>(point_covariance(pose, p, Z).trace()));
    }
  }
  io::PointTable table = io::from_scan(fused);
  io::FieldColumn& lidar = table.add_field("lidar", io::ScalarType::kU8);
  if (!lidar_index.empty()) std::memcpy(lidar.data.data(), lidar_index.data(), lidar_index.size());
  io::add_f32_field(table, "uncertainty", uncertainty);
  return table;
}

void write_fused(const fs::path& folder, const std::vector<PerturbedLidar>& lidars, const PerturbSpec& spec, const fs::path& out,
                 const std::function<void(int, int)>& progress) {
  const io::FrameSource source = io::FrameSource::dataset(folder);
  fs::create_directories(out / "fused");
  for (std::size_t k = 0; k < source.frames(); ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.pcd", k);
    io::PcdCloud cloud;
    cloud.table = fused_cloud(source.read(k), lidars, spec);
    io::write_pcd(out / "fused" / name, cloud);
    if (progress) progress(static_cast<int>(k) + 1, static_cast<int>(source.frames()));
  }
}

}  // namespace

std::vector<PerturbedLidar> write_perturbed_dataset(const fs::path& dataset_path, const PerturbSpec& spec, const fs::path& out,
                                                    const std::function<void(int, int)>& progress) {
  const fs::path folder = dataset_folder(dataset_path);
  io::Dataset dataset = io::read_dataset_yaml(dataset_path);
  std::vector<PerturbedLidar> lidars = true_extrinsics(dataset, folder);
  std::mt19937_64 rng(spec.seed);
  for (auto& lidar : lidars) {
    if (lidar.perturbed) lidar.T_base_lidar_perturbed = sample_perturbed_extrinsic(lidar.T_base_lidar_true, spec.prior, rng);
  }

  copy_dataset_files(folder, out, spec.link);
  for (std::size_t j = 0; j < dataset.lidars.size(); ++j) {
    dataset.lidars[j].initial_extrinsic = lidars[j].T_base_lidar_perturbed;
    dataset.lidars[j].scans = kept_path(dataset.lidars[j].scans, folder);
  }
  dataset.times = kept_path(dataset.times, folder);
  fs::create_directories(out / "groundtruth");
  if (!dataset.groundtruth.extrinsics) {
    io::Extrinsics truth;
    truth.base = dataset.base;
    for (const auto& lidar : lidars) truth.lidars.push_back({lidar.name, lidar.T_base_lidar_true, std::nullopt});
    io::write_extrinsics(out / "groundtruth" / "extrinsics.yaml", truth);
    dataset.groundtruth.extrinsics = "groundtruth/extrinsics.yaml";
  }
  for (auto* path : {&dataset.groundtruth.trajectory, &dataset.groundtruth.extrinsics, &dataset.groundtruth.boxes}) {
    if (*path) *path = kept_path(**path, folder);
  }
  const nlohmann::json record = perturbation_json(spec, lidars);
  io::write_atomically(out / "groundtruth" / "perturbation.json", [&](std::ostream& o) { o << record.dump(1) << '\n'; });
  io::write_extrinsics(out / "extrinsics_perturbed.yaml", perturbed_extrinsics(dataset.base, spec, lidars));
  if (spec.fused) write_fused(folder, lidars, spec, out, progress);
  io::write_dataset_yaml(out / "dataset.yaml", dataset);
  return lidars;
}

}  // namespace mlidar::pipelines
