#include "mlidar/pipelines/autocalib_job.hpp"

#include <algorithm>
#include <chrono>

#include <memory>

#include <tbb/global_control.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/pipelines/autocalib_report.hpp"
#include "mlidar/pipelines/frame_gaps.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {
namespace {

namespace fs = std::filesystem;

struct LidarMotion {
  std::vector<SE3> T_world_lidar;  ///< per frame, the LiDAR's own odometry
  std::vector<bool> lost;          ///< lost by its odometry, or no scan there
  std::vector<Scan> ground_scans;  ///< the scans of the ground frames
};

std::vector<std::size_t> ground_frame_indices(std::size_t frames, int wanted) {
  std::vector<std::size_t> indices;
  const std::size_t n = std::min(frames, static_cast<std::size_t>(std::max(wanted, 0)));
  for (std::size_t i = 0; i < n; ++i) indices.push_back(i * frames / n);
  return indices;
}

Scan empty_scan(double stamp) {
  Scan scan;
  scan.stamp = stamp;
  return scan;
}

/// Stage 1 (thesis 3.4.1), frame by frame so that each cloud is parsed once: each LiDAR's own motion (odometry
/// with it alone; only the base's when refining alone), and what the refinement needs later (the base's local-map
/// features, the targets' overlap subsamples).
class MotionStage {
 public:
  MotionStage(const io::FrameSource& source, std::size_t base, bool run_handeye, bool run_refine, const RefineConfig& refine)
      : base_(base), step_(static_cast<std::size_t>(std::max(refine.frame_step, 1))), voxel_m_(refine.overlap_voxel_m) {
    const auto& lidars = source.lidars();
    motions.resize(lidars.size());
    odometries_.resize(lidars.size());
    for (std::size_t i = 0; i < lidars.size(); ++i) {
      if (i == base || run_handeye)
        odometries_[i] = std::make_unique<slam::Odometry>(
            slam::OdometryConfig{}, std::vector<slam::LidarSetup>{{lidars[i].name, lidars[i].model, SE3::identity()}});
    }
    if (!run_refine) return;
    base_maps.emplace(lidars[base].name, lidars[base].model, refine);
    for (std::size_t i = 0; i < lidars.size(); ++i)
      targets.push_back({lidars[i].name, lidars[i].model, std::vector<std::optional<std::vector<Eigen::Vector3f>>>(source.frames()),
                         [&source, i](std::size_t k) { return source.read_scan(k, i); }});
  }

  void add(io::SourceFrame& frame, bool ground) {
    for (std::size_t i = 0; i < odometries_.size(); ++i) {
      if (!odometries_[i]) continue;
      const std::optional<Scan>& scan = frame.scans[i];
      const slam::FrameResult result = odometries_[i]->process(Frame{frame.stamp, {scan ? *scan : empty_scan(frame.stamp)}});
      motions[i].T_world_lidar.push_back(result.T_world_base);
      motions[i].lost.push_back(result.flagged() || !scan);
      if (ground && scan) motions[i].ground_scans.push_back(*scan);
    }
    if (base_maps) add_refine_inputs(frame);
  }

  /// After the last frame.
  void finish() {
    if (base_maps && pending_base_) base_maps->add_scan(motions[base_].lost.size() - 1, *pending_base_);
    pending_base_.reset();
  }

  std::vector<LidarMotion> motions;        ///< source order; empty for LiDARs not run
  std::optional<BaseLocalMaps> base_maps;  ///< when refine runs
  std::vector<TargetFrames> targets;       ///< source order (the base's entry unused), when refine runs

 private:
  void add_refine_inputs(io::SourceFrame& frame) {
    const std::size_t k = frame.index;
    base_maps->add_pose(frame.stamp, motions[base_].T_world_lidar.back(), motions[base_].lost.back());
    if (pending_base_) base_maps->add_scan(k - 1, *pending_base_);  // its deskew velocity needed pose k
    pending_base_ = std::move(frame.scans[base_]);
    if (k % step_ != 0) return;
    for (std::size_t i = 0; i < targets.size(); ++i)
      if (i != base_ && frame.scans[i]) targets[i].overlap_points[k] = overlap_subsample(*frame.scans[i], voxel_m_);
  }

  std::size_t base_;
  std::size_t step_;
  double voxel_m_;
  std::vector<std::unique_ptr<slam::Odometry>> odometries_;
  std::optional<Scan> pending_base_;  ///< the base scan of the previous frame
};

/// A_k = T_{a_{k-s} a_k}, B_k = T_{b_{k-s} b_k}; frames lost by either odometry are skipped.
std::vector<calib::MotionPair> motion_pairs(const LidarMotion& a, const LidarMotion& b, int stride) {
  std::vector<calib::MotionPair> pairs;
  const auto s = static_cast<std::size_t>(stride);
  for (std::size_t k = s; k < a.T_world_lidar.size(); ++k) {
    if (a.lost[k] || a.lost[k - s] || b.lost[k] || b.lost[k - s]) continue;
    pairs.push_back({a.T_world_lidar[k - s].inverse() * a.T_world_lidar[k], b.T_world_lidar[k - s].inverse() * b.T_world_lidar[k]});
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

LidarCalibration calibrate_against_base(const std::string& name, const LidarMotion& base, const LidarMotion& own, const AutoCalibJob& job) {
  LidarCalibration out;
  out.name = name;
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

/// The output frame: the dataset's base frame, or with --base that LiDAR's.
BaseFrame output_frame(const AutoCalibJob& job, const io::FrameSource& source) {
  if (job.base.empty()) return base_frame(source);
  const std::optional<std::size_t> lidar = source.find(job.base);
  if (!lidar) throw UsageError("--base: no LiDAR '" + job.base + "' among the input's LiDARs");
  return {job.base, *lidar, SE3::identity(), true};
}

/// LiDAR i's extrinsic as dataset.yaml gives it, in the output frame (nullopt when it gives none, or when --base
/// names a LiDAR whose own extrinsic it does not give).
std::optional<SE3> dataset_extrinsic(const io::FrameSource& source, std::size_t i, const BaseFrame& frame) {
  const auto& lidars = source.lidars();
  if (i == frame.reference) return frame.T_base_reference;
  if (!lidars[i].initial_extrinsic) return std::nullopt;
  if (frame.name == source.dataset_info()->base) return lidars[i].initial_extrinsic;
  const bool base_is_lidar = source.find(source.dataset_info()->base).has_value();
  const std::optional<SE3> T_B_X = lidars[frame.reference].initial_extrinsic;
  if (!T_B_X && !base_is_lidar) return std::nullopt;
  return T_B_X.value_or(SE3::identity()).inverse() * *lidars[i].initial_extrinsic;
}

void check_options(const AutoCalibJob& job) {
  if (job.stage == AutoCalibStage::refine && job.init.empty()) throw UsageError("--stage refine needs --init extrinsics.yaml");
  if (job.stage == AutoCalibStage::handeye && !job.init.empty())
    throw UsageError("--init has no use with --stage handeye (hand-eye needs no initial guess)");
  if (job.pair_stride < 1) throw UsageError("pair_stride must be >= 1");
  if (job.threads < 0) throw UsageError("--threads must be >= 0");
}

/// T_base_lidar from --init, whatever base that file uses (it must list ours, or use it as its base).
std::optional<SE3> init_extrinsic(const io::Extrinsics& init, const std::filesystem::path& source, const std::string& base,
                                  const std::string& lidar) {
  const io::LidarExtrinsic* target = init.find(lidar);
  if (target == nullptr) return std::nullopt;
  if (init.base == base) return target->T_base_lidar;
  const io::LidarExtrinsic* ours = init.find(base);
  if (ours == nullptr)
    throw InputError(source.string(), "lidars." + base, "missing; --init must list the base LiDAR or use it as its base");
  return ours->T_base_lidar.inverse() * target->T_base_lidar;
}

/// Stage 3 for every auxiliary LiDAR: from hand-eye's result when usable, else from --init.
void refine_all(const AutoCalibJob& job, const MotionStage& motion, std::size_t base, const std::optional<io::Extrinsics>& init,
                AutoCalibSummary& summary) {
  for (std::size_t i = 0; i < summary.lidars.size(); ++i) {
    LidarCalibration& c = summary.lidars[i];
    if (i == base) continue;
    std::optional<SE3> start;
    if (c.handeye_ran && c.usable) {
      start = c.T_base_lidar_handeye;
      c.refine_start = RefineStart::handeye;
    } else if (init) {
      start = init_extrinsic(*init, job.init, summary.base, c.name);
      if (!start && job.stage == AutoCalibStage::refine)
        throw InputError(job.init.string(), "lidars." + c.name, "missing; --stage refine needs every LiDAR's start");
      if (start) c.refine_start = RefineStart::init;
    }
    AppearanceCalibration appearance =
        calibrate_by_appearance(*motion.base_maps, motion.targets[i], start, job.refine, job.search ? &job.start_search : nullptr);
    c.refine = std::move(appearance.from_start);
    c.search = std::move(appearance.search);
    if (appearance.from_search) {
      c.refine_unsearched = std::move(c.refine);
      if (c.refine_unsearched) c.unsearched_start = c.refine_start;
      c.refine = std::move(appearance.from_search);
      c.refine_start = RefineStart::search;
    }
    // A start the appearance cannot confirm is not a result.
    c.usable = c.refine && c.refine->verdict == RefineVerdict::ok;
    if (!c.usable) continue;
    c.T_base_lidar = c.refine->T_base_target;
    c.covariance = c.refine->covariance();
  }
}

/// Why LiDAR c is not calibrated and what to try, from the stage that stopped it.
void explain(const AutoCalibJob& job, LidarCalibration& c) {
  using calib::HandEyeVerdict;
  if (c.refine && c.refine->verdict != RefineVerdict::ok) {
    c.reason = std::string("refine ") + to_string(c.refine->verdict) + ": " + c.refine->message;
    if (c.refine_start == RefineStart::search)
      c.reason = "the refinement from the appearance search's best start (" + c.search->label + ") failed, " + c.reason;
    else if (c.search)
      c.reason += "; the appearance search found no start (no search frame with a ground in the base's map)";
    c.advice = c.refine->verdict == RefineVerdict::no_overlap
                   ? "it shares no view with the base LiDAR's local maps from this start: give --init closer to the mounting"
                   : "more frames where both LiDARs see the same surfaces, a smaller refine.frame_step, or a better --init";
    return;
  }
  if (c.handeye_ran && !c.usable) {
    c.reason = "hand-eye " + std::string(calib::to_string(c.hand_eye.verdict)) + ": " + c.hand_eye.message;
    c.advice = c.hand_eye.verdict == HandEyeVerdict::planar_motion
                   ? "planar motion leaves the height unobservable and no ground was found: give --init (and --stage refine)"
                   : "drive with more turning (rotations about two axes), or give --init and --stage refine";
    return;
  }
  if (!c.usable) {
    c.reason = "no start for the refinement";
    c.advice = job.init.empty() ? "give --init with this LiDAR" : "list this LiDAR in --init";
  }
}

}  // namespace

std::string_view to_string(AutoCalibStage stage) {
  switch (stage) {
    case AutoCalibStage::handeye:
      return "handeye";
    case AutoCalibStage::refine:
      return "refine";
    case AutoCalibStage::all:
      return "all";
  }
  return "unknown";
}

std::string_view to_string(RefineStart start) {
  switch (start) {
    case RefineStart::none:
      return "";
    case RefineStart::handeye:
      return "handeye";
    case RefineStart::init:
      return "init";
    case RefineStart::search:
      return "search";
  }
  return "";
}

bool AutoCalibSummary::all_usable() const {
  return std::all_of(lidars.begin(), lidars.end(), [](const auto& l) { return l.usable; });
}

AutoCalibSummary run_autocalib_job(const AutoCalibJob& job, const std::function<void(const std::string&, int, int)>& progress) {
  check_options(job);
  std::unique_ptr<tbb::global_control> threads;
  if (job.threads > 0)
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(job.threads));
  const auto start = std::chrono::steady_clock::now();
  const io::FrameSource source = open_frames(job.dataset, job.bag, job.bag_options);
  AutoCalibSummary summary;
  summary.frame = output_frame(job, source);
  const std::size_t base_index = summary.frame.reference;
  summary.base = source.lidars()[base_index].name;
  std::optional<io::Extrinsics> init;
  if (!job.init.empty()) init = io::read_extrinsics(job.init);
  const bool run_handeye = job.stage != AutoCalibStage::refine;
  const bool run_refine = job.stage != AutoCalibStage::handeye;
  const auto ground_frames = ground_frame_indices(source.frames(), job.ground_frames);
  FrameGaps gaps(source);
  // Stage 1: each LiDAR's own motion (only the base's when refining alone).
  MotionStage motion(source, base_index, run_handeye, run_refine, job.refine);
  for (std::size_t k = 0; k < source.frames(); ++k) {
    io::SourceFrame frame = source.read(k);
    gaps.add(frame.skipped);
    motion.add(frame, std::find(ground_frames.begin(), ground_frames.end(), k) != ground_frames.end());
    if (progress) progress("frames", static_cast<int>(k + 1), static_cast<int>(source.frames()));
  }
  motion.finish();
  // Stage 2: hand-eye per auxiliary LiDAR.
  for (std::size_t i = 0; i < source.lidars().size(); ++i) {
    LidarCalibration c;
    c.name = source.lidars()[i].name;
    if (i != base_index && run_handeye) c = calibrate_against_base(c.name, motion.motions[base_index], motion.motions[i], job);
    for (const bool lost : motion.motions[i].lost) c.odometry_lost_frames += lost ? 1 : 0;
    summary.lidars.push_back(std::move(c));
  }
  // Stage 3: appearance refinement.
  if (run_refine) refine_all(job, motion, base_index, init, summary);
  for (std::size_t i = 0; i < summary.lidars.size(); ++i) {
    LidarCalibration& c = summary.lidars[i];
    c.given = dataset_extrinsic(source, i, summary.frame);
    if (init && i != base_index) {
      if (const auto from_init = init_extrinsic(*init, job.init, summary.base, c.name))
        c.given = summary.frame.extrinsic_to_base(*from_init);
    }
    explain(job, c);
  }
  summary.gaps = gaps.summary_lines();
  summary.base_failure = gaps.base_failure(job.max_base_gaps, base_index);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_autocalib_outputs(job, summary, gaps.json());
  return summary;
}

}  // namespace mlidar::pipelines
