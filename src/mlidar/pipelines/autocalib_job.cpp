#include "mlidar/pipelines/autocalib_job.hpp"

#include <algorithm>
#include <chrono>

#include <memory>

#include <tbb/global_control.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/pipelines/autocalib_report.hpp"
#include "mlidar/pipelines/odometry_job.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {
namespace {

namespace fs = std::filesystem;

struct LidarMotion {
  std::vector<SE3> T_world_lidar;  ///< per frame, the LiDAR's own odometry
  std::vector<bool> lost;
  std::vector<Scan> ground_scans;  ///< the scans of the ground frames
};

std::vector<std::size_t> ground_frame_indices(std::size_t frames, int wanted) {
  std::vector<std::size_t> indices;
  const std::size_t n = std::min(frames, static_cast<std::size_t>(std::max(wanted, 0)));
  for (std::size_t i = 0; i < n; ++i) indices.push_back(i * frames / n);
  return indices;
}

/// Stage 1 (thesis 3.4.1): the LiDAR's own motion, odometry with it alone.
LidarMotion lidar_motion(const fs::path& folder, const io::DatasetLidar& lidar, std::span<const double> stamps,
                         std::span<const std::size_t> ground_frames,
                         const std::function<void(const std::string&, int, int)>& progress) {
  const auto clouds = natural_sorted_clouds(folder / lidar.scans);
  if (clouds.size() < stamps.size())
    throw InputError((folder / lidar.scans).string(), "scans",
                     "has " + std::to_string(clouds.size()) + " clouds for " + std::to_string(stamps.size()) + " stamps");
  slam::Odometry odometry({}, {{lidar.name, lidar.model, SE3::identity()}});
  LidarMotion motion;
  for (std::size_t k = 0; k < stamps.size(); ++k) {
    Frame frame;
    frame.stamp = stamps[k];
    frame.scans.push_back(load_dataset_scan(clouds[k], stamps[k]));
    const slam::FrameResult result = odometry.process(frame);
    motion.T_world_lidar.push_back(result.T_world_base);
    motion.lost.push_back(result.lost);
    if (std::find(ground_frames.begin(), ground_frames.end(), k) != ground_frames.end())
      motion.ground_scans.push_back(std::move(frame.scans.front()));
    if (progress) progress(lidar.name, static_cast<int>(k + 1), static_cast<int>(stamps.size()));
  }
  return motion;
}

/// A_k = T_{a_{k-s} a_k}, B_k = T_{b_{k-s} b_k}; frames lost by either odometry are skipped.
std::vector<calib::MotionPair> motion_pairs(const LidarMotion& a, const LidarMotion& b, int stride) {
  std::vector<calib::MotionPair> pairs;
  const auto s = static_cast<std::size_t>(stride);
  for (std::size_t k = s; k < a.T_world_lidar.size(); ++k) {
    if (a.lost[k] || a.lost[k - s] || b.lost[k] || b.lost[k - s]) continue;
    pairs.push_back({a.T_world_lidar[k - s].inverse() * a.T_world_lidar[k],
                     b.T_world_lidar[k - s].inverse() * b.T_world_lidar[k]});
  }
  return pairs;
}

/// The ground step replaces the unobservable variance along the axis by the
/// spread of the per-frame heights (over sqrt of their count).
Mat6 with_ground_variance(Mat6 covariance, const Vec3& axis, const calib::GroundHeightResult& ground) {
  const Mat3 P = Mat3::Identity() - axis * axis.transpose();
  const double n = static_cast<double>(std::max<std::size_t>(ground.frames_used, 1));
  const double variance = std::max(ground.spread_m * ground.spread_m, 1e-6) / n;
  covariance.topLeftCorner<3, 3>() = P * covariance.topLeftCorner<3, 3>() * P + variance * axis * axis.transpose();
  covariance.topRightCorner<3, 3>() = P * covariance.topRightCorner<3, 3>();
  covariance.bottomLeftCorner<3, 3>() = covariance.topRightCorner<3, 3>().transpose();
  return covariance;
}

/// General motion: the ground planes still measure the height along the
/// base's z (LiDARs mounted near level, thesis 3.3); fused with the hand-eye
/// estimate by their variances along that axis (a scalar Kalman update of the
/// translation; the rotation is left as hand-eye found it, since odometry
/// biases make its correlation with the height unreliable).
void fuse_ground_height(const LidarMotion& base, const LidarMotion& own, const AutoCalibJob& job, LidarCalibration& out) {
  const Vec3 axis = Vec3::UnitZ();
  const calib::GroundHeightResult ground =
      calib::height_from_ground(base.ground_scans, own.ground_scans, out.T_base_lidar, axis, job.ground);
  if (ground.frames_used < 3) return;
  const double n = static_cast<double>(ground.frames_used);
  const double variance_ground = std::max(ground.spread_m * ground.spread_m, 1e-6) / n;
  const Vec6 h = (Vec6() << axis, Vec3::Zero()).finished();
  const double variance_hand_eye = h.dot(out.covariance * h);
  Vec6 gain = out.covariance * h / (variance_hand_eye + variance_ground);
  gain.tail<3>().setZero();
  out.T_base_lidar = SE3(out.T_base_lidar.rotation(), out.T_base_lidar.translation() + gain.head<3>() * ground.shift_m);
  const Mat6 I_KH = Mat6::Identity() - gain * h.transpose();  // Joseph form: PSD for any gain
  out.covariance = I_KH * out.covariance * I_KH.transpose() + variance_ground * gain * gain.transpose();
  out.ground = ground;
}

LidarCalibration calibrate_against_base(const io::DatasetLidar& lidar, const LidarMotion& base, const LidarMotion& own,
                                        const AutoCalibJob& job) {
  LidarCalibration out;
  out.name = lidar.name;
  out.hand_eye = calib::solve_hand_eye(motion_pairs(base, own, job.pair_stride), job.hand_eye);
  out.T_base_lidar = out.hand_eye.T_a_b;
  // Pairs s frames apart overlap: each frame-to-frame motion enters s pairs,
  // so they carry about 1/s of the information the solver counts.
  out.covariance = out.hand_eye.covariance * static_cast<double>(job.pair_stride);
  using calib::HandEyeVerdict;
  out.usable = out.hand_eye.verdict == HandEyeVerdict::ok;
  if (out.hand_eye.verdict == HandEyeVerdict::planar_motion) {
    const Vec3& axis = out.hand_eye.planar_axis_a;
    out.ground = calib::height_from_ground(base.ground_scans, own.ground_scans, out.T_base_lidar, axis, job.ground);
    out.usable = out.ground->frames_used > 0;
    out.T_base_lidar = out.ground->T_a_b;
    if (out.usable) out.covariance = with_ground_variance(out.covariance, axis, *out.ground);
  } else if (out.usable) {
    fuse_ground_height(base, own, job, out);
  }
  out.handeye_ran = true;
  out.T_base_lidar_handeye = out.T_base_lidar;
  out.covariance_handeye = out.covariance;
  return out;
}

std::string base_name(const AutoCalibJob& job, const io::Dataset& dataset) {
  const auto has = [&](const std::string& name) {
    return std::any_of(dataset.lidars.begin(), dataset.lidars.end(), [&](const auto& l) { return l.name == name; });
  };
  if (!job.base.empty()) {
    if (!has(job.base)) throw UsageError("--base: no LiDAR '" + job.base + "' in " + (job.dataset / "dataset.yaml").string());
    return job.base;
  }
  return has(dataset.base) ? dataset.base : dataset.lidars.front().name;
}

void check_options(const AutoCalibJob& job) {
  if (job.stage != "handeye" && job.stage != "refine" && job.stage != "all")
    throw UsageError("--stage: expected handeye, refine or all (got '" + job.stage + "')");
  if (job.stage == "refine" && job.init.empty()) throw UsageError("--stage refine needs --init extrinsics.yaml");
  if (job.stage == "handeye" && !job.init.empty())
    throw UsageError("--init has no use with --stage handeye (hand-eye needs no initial guess)");
  if (job.pair_stride < 1) throw UsageError("pair_stride must be >= 1");
  if (job.threads < 0) throw UsageError("--threads must be >= 0");
}

/// T_base_lidar from --init, whatever base that file uses (it must list ours, or use it as its base).
std::optional<SE3> init_extrinsic(const io::Extrinsics& init, const std::filesystem::path& source,
                                  const std::string& base, const std::string& lidar) {
  const io::LidarExtrinsic* target = init.find(lidar);
  if (target == nullptr) return std::nullopt;
  if (init.base == base) return target->T_base_lidar;
  const io::LidarExtrinsic* ours = init.find(base);
  if (ours == nullptr)
    throw InputError(source.string(), "lidars." + base, "missing; --init must list the base LiDAR or use it as its base");
  return ours->T_base_lidar.inverse() * target->T_base_lidar;
}

LidarFrames lidar_frames(const fs::path& folder, const io::DatasetLidar& lidar) {
  return {lidar.name, lidar.model, folder / lidar.scans, natural_sorted_clouds(folder / lidar.scans)};
}

/// Stage 3 for every auxiliary LiDAR: from hand-eye's result when usable, else from --init.
void refine_all(const AutoCalibJob& job, const io::Dataset& dataset, std::span<const double> stamps,
                const LidarMotion& base_motion, const std::optional<io::Extrinsics>& init, AutoCalibSummary& summary) {
  const auto base_lidar = std::find_if(dataset.lidars.begin(), dataset.lidars.end(),
                                       [&](const auto& l) { return l.name == summary.base; });
  BaseLocalMaps base(lidar_frames(job.dataset, *base_lidar), {{stamps.begin(), stamps.end()}, base_motion.T_world_lidar,
                                                              base_motion.lost}, job.refine);
  for (std::size_t i = 0; i < dataset.lidars.size(); ++i) {
    LidarCalibration& c = summary.lidars[i];
    if (c.name == summary.base) continue;
    std::optional<SE3> start;
    if (c.handeye_ran && c.usable) {
      start = c.T_base_lidar_handeye;
      c.refine_start = "handeye";
    } else if (init) {
      start = init_extrinsic(*init, job.init, summary.base, c.name);
      if (!start && job.stage == "refine")
        throw InputError(job.init.string(), "lidars." + c.name, "missing; --stage refine needs every LiDAR's start");
      if (start) c.refine_start = "init";
    }
    if (!start) continue;  // hand-eye unusable and no --init: reported by its verdict
    c.refine = refine_against_base(base, lidar_frames(job.dataset, dataset.lidars[i]), *start, job.refine);
    if (c.refine->verdict != RefineVerdict::ok) {
      c.usable = c.refine_start == "handeye";  // hand-eye's result stands; an unrefined --init does not
      continue;
    }
    c.usable = true;
    c.T_base_lidar = c.refine->T_base_target;
    c.covariance = c.refine->average.covariance;
  }
}

}  // namespace

bool AutoCalibSummary::all_usable() const {
  return std::all_of(lidars.begin(), lidars.end(), [](const auto& l) { return l.usable; });
}

AutoCalibSummary run_autocalib_job(const AutoCalibJob& job,
                                   const std::function<void(const std::string&, int, int)>& progress) {
  check_options(job);
  std::unique_ptr<tbb::global_control> threads;
  if (job.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(job.threads));
  const auto start = std::chrono::steady_clock::now();
  const io::Dataset dataset = io::read_dataset_yaml(job.dataset / "dataset.yaml");
  const std::vector<double> stamps = io::read_times(job.dataset / dataset.times);
  AutoCalibSummary summary;
  summary.base = base_name(job, dataset);
  std::optional<io::Extrinsics> init;
  if (!job.init.empty()) init = io::read_extrinsics(job.init);
  const bool run_handeye = job.stage != "refine";
  const auto ground_frames = ground_frame_indices(stamps.size(), job.ground_frames);
  // Stage 1: each LiDAR's own motion (only the base's when refining alone).
  std::vector<LidarMotion> motions(dataset.lidars.size());
  std::size_t base_index = 0;
  for (std::size_t i = 0; i < dataset.lidars.size(); ++i) {
    const bool is_base = dataset.lidars[i].name == summary.base;
    if (is_base) base_index = i;
    if (is_base || run_handeye) motions[i] = lidar_motion(job.dataset, dataset.lidars[i], stamps, ground_frames, progress);
  }
  // Stage 2: hand-eye per auxiliary LiDAR.
  for (std::size_t i = 0; i < dataset.lidars.size(); ++i) {
    LidarCalibration c;
    c.name = dataset.lidars[i].name;
    if (i != base_index && run_handeye) c = calibrate_against_base(dataset.lidars[i], motions[base_index], motions[i], job);
    for (const bool lost : motions[i].lost) c.odometry_lost_frames += lost ? 1 : 0;
    summary.lidars.push_back(std::move(c));
  }
  // Stage 3: appearance refinement.
  if (job.stage != "handeye") refine_all(job, dataset, stamps, motions[base_index], init, summary);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_autocalib_outputs(job, summary);
  return summary;
}

}  // namespace mlidar::pipelines
