// The M-LOAM estimator in process, on simulated frames made in memory: its
// per-LiDAR states and their transitions (initializing -> calibrating ->
// trusted, a shock back to initializing), a LiDAR missing for 10 s, the
// planar-motion start, and given extrinsics with which no frame registers.
#include <algorithm>
#include <functional>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/core/conversions.hpp"
#include "mlidar/pipelines/slam_estimator.hpp"
#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/lidar_models.hpp"
#include "mlidar/sim/rig.hpp"
#include "mlidar/sim/scenes.hpp"
#include "mlidar/sim/trajectory.hpp"
#include "pose_error.hpp"

namespace mlidar::test {
namespace {

using pipelines::ExtrinsicSource;
using pipelines::LidarRole;
using pipelines::SlamEstimator;
using pipelines::SlamFrame;

/// A simulated drive of `rig` (its LiDARs in rig order, base first) through `scene`.
struct Drive {
  sim::SimRig rig;
  sim::SimTrajectory trajectory;
  std::vector<double> stamps;
  sim::Scene scene;
  std::uint64_t seed = 1;
};

/// `scene_frames` (0: frames): the scene is laid out along that many frames' path, as `simulate drive --frames` does.
Drive make_drive(const std::string& rig_name, const std::string& scene, const std::string& trajectory, int frames, std::uint64_t seed = 1,
                 int scene_frames = 0) {
  sim::SimRig rig = sim::named_rig(rig_name);
  const sim::SimTrajectory path = sim::SimTrajectory::named(trajectory, rig.base_height);
  std::vector<double> stamps;
  std::vector<Vec3> positions;
  for (int k = 0; k <= std::max(frames, scene_frames); ++k) {
    if (k < frames) stamps.push_back(path.start_time() + 0.1 * k);
    positions.push_back(path.T_world_base(path.start_time() + 0.1 * k).translation());
  }
  sim::Scene world = sim::make_scene(scene, seed, positions);
  return {std::move(rig), path, std::move(stamps), std::move(world), seed};
}

/// LiDAR i's scan at frame k as the frame source gives it (stamp at its earliest point, times from there).
Scan sweep(const Drive& drive, const sim::SimLidar& lidar, std::size_t k, std::size_t i) {
  Scan scan = sim::simulate_sweep(drive.scene, lidar, drive.trajectory, drive.stamps[k], sim::sweep_seed(drive.seed, k, i)).scan;
  const float earliest = *std::min_element(scan.time.begin(), scan.time.end());
  scan.stamp += earliest;
  for (float& t : scan.time) t -= earliest;
  return scan;
}

/// The estimator's setups: the base as given, the others with their extrinsic's rotation off by 5 deg (online
/// uses only that rotation, as the own odometry's up).
std::vector<slam::LidarSetup> setups(const sim::SimRig& rig) {
  std::vector<slam::LidarSetup> out;
  for (std::size_t i = 0; i < rig.lidars.size(); ++i) {
    const SE3 tilt(so3_exp(Vec3(0.0, deg_to_rad(i == 0 ? 0.0 : 5.0), 0.0)), Vec3::Zero());
    out.push_back({rig.lidars[i].name, rig.lidars[i].model, rig.lidars[i].T_base_lidar * tilt});
  }
  return out;
}

/// Runs the estimator over the drive; `scan_of(k, i, lidar)` may move a LiDAR or drop its scan.
std::vector<SlamFrame> run(SlamEstimator& estimator, const Drive& drive,
                           const std::function<std::optional<Scan>(std::size_t, std::size_t, sim::SimLidar)>& scan_of) {
  std::vector<SlamFrame> frames;
  for (std::size_t k = 0; k < drive.stamps.size(); ++k) {
    std::vector<std::optional<Scan>> scans;
    for (std::size_t i = 0; i < drive.rig.lidars.size(); ++i) scans.push_back(scan_of(k, i, drive.rig.lidars[i]));
    frames.push_back(estimator.process(drive.stamps[k], scans));
  }
  return frames;
}

/// The frames where LiDAR j's role (after the frame) differs from the frame before, with the role it took.
std::vector<std::pair<std::size_t, LidarRole>> role_changes(const std::vector<SlamFrame>& frames, std::size_t j, LidarRole initial) {
  std::vector<std::pair<std::size_t, LidarRole>> changes;
  LidarRole before = initial;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].lidars[j].role != before) changes.emplace_back(k, frames[k].lidars[j].role);
    before = frames[k].lidars[j].role;
  }
  return changes;
}

TEST(SlamEstimator, InitializesCalibratesTrustsAndAShockSendsItBack) {
  // rhd handheld on the campus. Algorithm 1 after 10 accepted windows and a shock baseline of 10 frames keep
  // the run short; the transitions are what is checked, not the accuracy (the CLI tests do that).
  constexpr std::size_t kFrames = 110, kShockFrame = 85;
  const Drive drive = make_drive("rhd", "campus", "handheld", static_cast<int>(kFrames));
  pipelines::SlamConfig config;
  config.convergence.accepted_needed = 10;
  config.shock.min_history = 10;
  SlamEstimator estimator(config, setups(drive.rig), ExtrinsicSource::online);
  EXPECT_EQ(estimator.track(0).role(), LidarRole::trusted);
  EXPECT_EQ(estimator.track(1).role(), LidarRole::initializing);
  Vec6 shock;  // Table 4.6: 10 deg about each axis, 0.1 m along each
  shock << 0.1, 0.1, 0.1, deg_to_rad(10.0), deg_to_rad(10.0), deg_to_rad(10.0);
  const std::vector<SlamFrame> frames = run(estimator, drive, [&](std::size_t k, std::size_t i, sim::SimLidar lidar) {
    if (i == 1 && k >= kShockFrame) lidar.T_base_lidar = lidar.T_base_lidar * SE3::exp(shock);
    return std::optional(sweep(drive, lidar, k, i));
  });
  const auto changes = role_changes(frames, 1, LidarRole::initializing);
  ASSERT_EQ(changes.size(), 3U) << "expected calibrating, trusted, initializing";
  EXPECT_EQ(changes[0].second, LidarRole::calibrating);
  EXPECT_EQ(changes[1].second, LidarRole::trusted);
  EXPECT_EQ(changes[2].second, LidarRole::initializing);
  EXPECT_LT(changes[1].first, kShockFrame);
  EXPECT_GE(changes[2].first, kShockFrame);  // the trigger needs 5 high frames in a row
  EXPECT_LE(changes[2].first, kShockFrame + 10);
  // The trusted set changes exactly at the convergence and at the shock.
  for (std::size_t k = 0; k < frames.size(); ++k) EXPECT_EQ(frames[k].trusted_changed, k == changes[1].first || k == changes[2].first) << k;
  for (std::size_t k = 0; k < frames.size(); ++k) EXPECT_EQ(frames[k].calibrating, frames[k].lidars[1].role != LidarRole::trusted) << k;

  const auto reports = estimator.lidar_reports(frames);
  const pipelines::SlamLidarReport& right = reports[1];
  EXPECT_EQ(right.role, LidarRole::initializing);
  EXPECT_EQ(right.initialized_frame, changes[0].first);
  EXPECT_EQ(right.converged_frame, changes[1].first);
  EXPECT_EQ(right.first_converged_frame, changes[1].first);
  EXPECT_EQ(right.restarts, 1U);
  ASSERT_FALSE(right.shock_frames.empty());
  EXPECT_EQ(right.shock_frames.front(), changes[2].first);
  EXPECT_FALSE(right.covariance.has_value()) << "a shocked LiDAR's covariance no longer holds";
  EXPECT_NE(right.translation_start, pipelines::TranslationStart::none);  // a start happened (here from t = 0: campus)
  EXPECT_TRUE(reports[0].shock_frames.empty());
  EXPECT_EQ(reports[0].role, LidarRole::trusted);
}

TEST(SlamEstimator, FeatureSelectionWaitsUntilEveryLidarIsTrusted) {
  // Greedy selection with online calibration: while the right LiDAR calibrates, the odometry (and the right
  // LiDAR's own, the hand-eye's input) registers every feature: frame for frame the run without selection, trusted
  // at the same frame; it selects from the frame after.
  constexpr std::size_t kFrames = 80;
  const Drive drive = make_drive("rhd", "campus", "handheld", static_cast<int>(kFrames));
  pipelines::SlamConfig config;
  config.convergence.accepted_needed = 10;
  pipelines::SlamConfig selecting = config;
  selecting.odometry.registration.selection.method = slam::SelectionMethod::kGreedy;
  SlamEstimator with(selecting, setups(drive.rig), ExtrinsicSource::online);
  const auto scan_of = [&](std::size_t k, std::size_t i, const sim::SimLidar& lidar) { return std::optional(sweep(drive, lidar, k, i)); };
  const std::vector<SlamFrame> frames = run(with, drive, scan_of);
  const auto changes = role_changes(frames, 1, LidarRole::initializing);
  ASSERT_GE(changes.size(), 2U);
  ASSERT_EQ(changes[1].second, LidarRole::trusted);
  const std::size_t trusted_from = changes[1].first + 1;  // the first frame registered with both LiDARs trusted
  ASSERT_LT(trusted_from + 5, kFrames) << "the calibration should converge well inside the drive";
  SlamEstimator without(config, setups(drive.rig), ExtrinsicSource::online);
  for (std::size_t k = 0; k < kFrames; ++k) {
    if (k < trusted_from) {
      std::vector<std::optional<Scan>> scans;
      for (std::size_t i = 0; i < drive.rig.lidars.size(); ++i) scans.push_back(scan_of(k, i, drive.rig.lidars[i]));
      const SlamFrame plain = without.process(drive.stamps[k], scans);
      EXPECT_EQ(frames[k].T_world_base.matrix(), plain.T_world_base.matrix()) << "frame " << k;
      EXPECT_EQ(frames[k].lidars[1].role, plain.lidars[1].role) << "frame " << k;  // trusted at the same frame
      // The calibration windows start from the hand-eye on the right LiDAR's own odometry: the same estimates.
      ASSERT_EQ(frames[k].lidars[1].window_estimate.has_value(), plain.lidars[1].window_estimate.has_value()) << "frame " << k;
      if (plain.lidars[1].window_estimate) {
        EXPECT_EQ(frames[k].lidars[1].window_estimate->matrix(), plain.lidars[1].window_estimate->matrix()) << "frame " << k;
      }
      EXPECT_FALSE(frames[k].selection.has_value()) << "frame " << k;
    } else {
      EXPECT_TRUE(frames[k].selection.has_value()) << "frame " << k;
    }
  }
}

TEST(SlamEstimator, ALidarMissingForTenSecondsAddsNoMotionPairAcrossTheGap) {
  constexpr std::size_t kFrames = 130, kGapStart = 10, kGapEnd = 110;  // 100 frames at 10 Hz
  const Drive drive = make_drive("rhd", "campus", "handheld", static_cast<int>(kFrames));
  SlamEstimator estimator(pipelines::SlamConfig{}, setups(drive.rig), ExtrinsicSource::online);
  std::vector<SlamFrame> frames;
  std::size_t pairs_before_gap = 0, pairs_after_gap = 0;
  frames = run(estimator, drive, [&](std::size_t k, std::size_t i, const sim::SimLidar& lidar) -> std::optional<Scan> {
    if (i == 1 && k == kGapStart) pairs_before_gap = estimator.lidar_reports(frames).at(1).initialization.pairs_seen;
    // A pair needs kPairStride + 1 scans without a gap: none may be added before frame kGapEnd + kPairStride.
    if (i == 1 && k == kGapEnd + pipelines::kPairStride) pairs_after_gap = estimator.lidar_reports(frames).at(1).initialization.pairs_seen;
    if (i == 1 && k >= kGapStart && k < kGapEnd) return std::nullopt;
    return sweep(drive, lidar, k, i);
  });
  ASSERT_EQ(frames.size(), kFrames);
  EXPECT_GT(pairs_before_gap, 0U);
  EXPECT_EQ(pairs_after_gap, pairs_before_gap) << "a motion pair spanned the gap";
  for (std::size_t k = 0; k < kFrames; ++k) {
    EXPECT_EQ(frames[k].lidars[1].scan_missing, k >= kGapStart && k < kGapEnd) << k;
    EXPECT_FALSE(frames[k].lost) << "the base alone carried the odometry through frame " << k;
  }
  const auto reports = estimator.lidar_reports(frames);
  EXPECT_EQ(reports[1].missing_frames, kGapEnd - kGapStart);
  EXPECT_EQ(reports[0].missing_frames, 0U);
  // Pairs resume once kPairStride + 1 frames follow the gap (its own odometry restarted at the first of them).
  EXPECT_GT(reports[1].initialization.pairs_seen, pairs_after_gap);
  // The base's poses stay on the truth while the right LiDAR is gone: within 5 cm of the simulated path's
  // displacement between the gap's ends.
  const SE3 truth_start = drive.trajectory.T_world_base(drive.stamps[kGapStart]);
  const SE3 truth_end = drive.trajectory.T_world_base(drive.stamps[kGapEnd]);
  const SE3 estimated = frames[kGapStart].T_world_base.inverse() * frames[kGapEnd].T_world_base;
  EXPECT_LT(translation_error_m(truth_start.inverse() * truth_end, estimated), 0.05);
}

TEST(SlamEstimator, PlanarMotionStartsFromTheObservableDirectionsAndNamesTheOthers) {
  // rv's top and front LiDARs on a vehicle: every rotation is about the vertical. The start is eq 3.8-3.12 and
  // the ground planes; the rotation about the axis and the translation along it are named as not observable
  // from motion.
  constexpr std::size_t kFrames = 60;
  Drive drive = make_drive("rv", "campus", "vehicle", static_cast<int>(kFrames));
  drive.rig.lidars.resize(2);  // top (base) and the next one in rig order
  SlamEstimator estimator(pipelines::SlamConfig{}, setups(drive.rig), ExtrinsicSource::online);
  const std::vector<SlamFrame> frames = run(
      estimator, drive, [&](std::size_t k, std::size_t i, const sim::SimLidar& lidar) { return std::optional(sweep(drive, lidar, k, i)); });
  const auto changes = role_changes(frames, 1, LidarRole::initializing);
  ASSERT_FALSE(changes.empty()) << "never left initializing";
  EXPECT_EQ(changes[0].second, LidarRole::calibrating);
  const pipelines::SlamLidarReport report = estimator.lidar_reports(frames).at(1);
  EXPECT_TRUE(report.initialization.planar_motion);
  EXPECT_EQ(report.axis_translation_source, pipelines::AxisTranslationSource::ground_planes);
  ASSERT_FALSE(report.unobservable_from_motion.empty());
  EXPECT_NE(report.unobservable_from_motion[0].find("translation along the rotation axis"), std::string::npos);
  // The planar start is close enough for the window (its gates are 1.0 / 0.3 m).
  EXPECT_LT(translation_error_m(drive.rig.lidars[1].T_base_lidar, report.T_base_lidar), 0.3);
  EXPECT_LT(rotation_error_deg(drive.rig.lidars[1].T_base_lidar, report.T_base_lidar), 2.0);
}

TEST(SlamEstimator, NoFrameRegisteredWithTheGivenExtrinsicsSendsThemToCalibration) {
  // rv's top and front on the scene of `simulate drive --frames 300 --seed 2`, the front given with Table 4.6's
  // shock (10 deg about each axis, 0.1 m along each), fixed: at 7.5 m/s every frame after the first is lost
  // (measured: 299 of 300 with the check off), so the residual ratio never sees a frame.
  constexpr std::size_t kFrames = 12;
  Drive drive = make_drive("rv", "campus", "vehicle", static_cast<int>(kFrames), 2, 300);
  drive.rig.lidars.resize(2);
  std::vector<slam::LidarSetup> given;
  for (const sim::SimLidar& lidar : drive.rig.lidars) given.push_back({lidar.name, lidar.model, lidar.T_base_lidar});
  const double angle = deg_to_rad(10.0);
  given[1].T_base_lidar = SE3(given[1].T_base_lidar.rotation() * so3_exp(Vec3(angle, angle, angle)),
                              given[1].T_base_lidar.translation() + Vec3(0.1, 0.1, 0.1));
  const auto scan_of = [&](std::size_t k, std::size_t i, const sim::SimLidar& lidar) { return std::optional(sweep(drive, lidar, k, i)); };

  pipelines::SlamConfig unchecked;
  unchecked.extrinsic_check.residual.residual_ratio = 0.0;
  SlamEstimator as_given(unchecked, given, ExtrinsicSource::fixed);
  const std::vector<SlamFrame> lost = run(as_given, drive, scan_of);
  for (std::size_t k = 1; k < kFrames; ++k) EXPECT_TRUE(lost[k].lost) << "frame " << k << ": not the case this test is about";

  SlamEstimator checked(pipelines::SlamConfig{}, given, ExtrinsicSource::fixed);
  const std::vector<SlamFrame> frames = run(checked, drive, scan_of);
  const std::size_t verdict = SlamEstimator::kLostFromStartFrames;
  for (std::size_t k = 1; k <= verdict; ++k) EXPECT_TRUE(frames[k].lost) << "frame " << k;
  EXPECT_TRUE(frames[verdict].lidars[1].extrinsic_disagrees);
  EXPECT_TRUE(frames[verdict].trusted_changed);
  const auto& disagreement = checked.track(1).disagreement();
  ASSERT_TRUE(disagreement.has_value());
  EXPECT_TRUE(disagreement->frames_lost);
  EXPECT_TRUE(disagreement->recalibrated);
  EXPECT_EQ(disagreement->frame, verdict);
  EXPECT_EQ(frames[verdict].lidars[1].role, LidarRole::calibrating);
  // A stream goes on in place: after restart_after_lost (5) failed registrations the next frame starts a new map, the
  // base's alone now, and the frames after it are registered again, their motion since the restart the truth's.
  const std::size_t restart = verdict + 1;
  EXPECT_TRUE(frames[restart].map_restarted);
  EXPECT_TRUE(frames[restart].lost);
  const auto truth_at = [&](std::size_t k) { return drive.trajectory.T_world_base(drive.stamps[k]); };
  for (std::size_t k = restart + 1; k < kFrames; ++k) {
    EXPECT_FALSE(frames[k].lost) << "frame " << k;
    const SE3 truth_motion = truth_at(restart).inverse() * truth_at(k);
    EXPECT_LT(translation_error_m(truth_motion, frames[restart].T_world_base.inverse() * frames[k].T_world_base), 0.05) << "frame " << k;
  }
  // Told from the first frame (what `mlidar slam` does next: the run started again), the base registers alone
  // while the front calibrates, every frame near the truth; the LiDAR is not judged again.
  SlamEstimator told(pipelines::SlamConfig{}, given, ExtrinsicSource::fixed,
                     {std::nullopt, pipelines::ExtrinsicDisagreement{.frame = verdict, .residual_ratio = -1.0, .frames_lost = true}});
  const std::vector<SlamFrame> from_start = run(told, drive, scan_of);
  EXPECT_EQ(from_start[0].lidars[1].role, LidarRole::calibrating);
  const SE3 T_first_world = drive.trajectory.T_world_base(drive.stamps[0]).inverse();
  for (std::size_t k = 1; k < kFrames; ++k) {
    EXPECT_FALSE(from_start[k].lost) << "frame " << k;
    EXPECT_FALSE(from_start[k].lidars[1].extrinsic_disagrees) << "frame " << k;
    const SE3 truth = T_first_world * drive.trajectory.T_world_base(drive.stamps[k]);
    EXPECT_LT(translation_error_m(truth, from_start[k].T_world_base), 0.05) << "frame " << k;
  }
  EXPECT_TRUE(told.track(1).disagreement()->from_first_frame);
}

/// A config under which the hand-eye never starts a LiDAR: its translation is never certain enough, and the
/// window never starts from t = 0; the appearance start after `appearance_after_frames` (0: never).
pipelines::SlamConfig hand_eye_held(std::size_t appearance_after_frames) {
  pipelines::SlamConfig config;
  config.initialization.translation_max_std_m = 1e-9;
  config.start.zero_translation_after_pairs = 0;
  config.start.appearance_after_frames = appearance_after_frames;
  return config;
}

TEST(SlamEstimator, AppearanceStartsALidarTheHandEyeHolds) {
  // rv's top and right LiDARs on a vehicle with the hand-eye held back (as the planar start's 0.46 m 1-sigma held
  // rv seed 5's left LiDAR): after 30 frames the LiDAR is calibrated by its appearance against the base's maps
  // of those frames, as `calibrate auto` does, and its window starts from there. Without the appearance start
  // the same run never leaves initializing (the control: the held config really holds it).
  constexpr std::size_t kFrames = 60, kAfter = 30;
  Drive drive = make_drive("rv", "campus", "vehicle", static_cast<int>(kFrames));
  drive.rig.lidars.resize(2);
  const auto scans = [&](std::size_t k, std::size_t i, const sim::SimLidar& lidar) { return std::optional(sweep(drive, lidar, k, i)); };

  SlamEstimator held(hand_eye_held(0), setups(drive.rig), ExtrinsicSource::online);
  const std::vector<SlamFrame> held_frames = run(held, drive, scans);
  EXPECT_TRUE(role_changes(held_frames, 1, LidarRole::initializing).empty()) << "the hand-eye started it: the control does not hold";
  EXPECT_TRUE(held.lidar_reports(held_frames).at(1).appearance_attempts.empty());

  SlamEstimator estimator(hand_eye_held(kAfter), setups(drive.rig), ExtrinsicSource::online);
  const std::vector<SlamFrame> frames = run(estimator, drive, scans);
  const auto changes = role_changes(frames, 1, LidarRole::initializing);
  ASSERT_FALSE(changes.empty()) << "never left initializing";
  EXPECT_EQ(changes[0], std::make_pair(kAfter, LidarRole::calibrating));
  const pipelines::SlamLidarReport report = estimator.lidar_reports(frames).at(1);
  EXPECT_EQ(report.translation_start, pipelines::TranslationStart::appearance);
  ASSERT_EQ(report.appearance_attempts.size(), 1U);
  const pipelines::AppearanceAttempt& attempt = report.appearance_attempts[0];
  EXPECT_TRUE(attempt.ok) << attempt.verdict << ": " << attempt.message;
  EXPECT_EQ(attempt.frame, kAfter);
  EXPECT_EQ(attempt.frames_used, kAfter + 1);  // frames 0-30, all kept
  ASSERT_TRUE(attempt.T_base_lidar.has_value());
  // The start is inside the window's gates (1.0 / 0.3 m, as for the planar start), from a hand-eye estimate with
  // no translation (the LiDAR is mounted about 1.3 m from the base), and the windows from it reach what a
  // calibration must (0.3 deg / 3 cm).
  const SE3& truth = drive.rig.lidars[1].T_base_lidar;
  ASSERT_GT(truth.translation().norm(), 1.0);
  EXPECT_LT(rotation_error_deg(truth, *attempt.T_base_lidar), 2.0);
  EXPECT_LT(translation_error_m(truth, *attempt.T_base_lidar), 0.3);
  std::size_t windows = 0;
  for (std::size_t k = kAfter + 1; k < kFrames; ++k) {
    const std::optional<SE3>& window = frames[k].lidars[1].window_estimate;
    if (!window) continue;
    ++windows;
    EXPECT_LT(rotation_error_deg(truth, *window), 0.3) << k;
    EXPECT_LT(translation_error_m(truth, *window), 0.03) << k;
  }
  EXPECT_GT(windows, (kFrames - kAfter) / 2);
}

TEST(AppearanceHistory, KeepsTheLastFramesAndTheOthersScansAtCandidateFramesOnly) {
  constexpr std::size_t kCapacity = 10, kStep = 5;
  pipelines::AppearanceHistory history(kCapacity, kStep);
  const auto scan_at = [](double stamp) {
    Scan scan;
    scan.stamp = stamp;
    scan.points = {Eigen::Vector3f(1.0F, 0.0F, 0.0F), Eigen::Vector3f(0.0F, 5.0F, 0.0F)};
    return scan;
  };
  for (std::size_t k = 0; k < 12; ++k) {
    const double stamp = 0.1 * static_cast<double>(k);
    // No base scan (the base's maps then keep nothing): this checks which frames and scans are kept.
    history.add(k, stamp, SE3::identity(), false, {std::nullopt, scan_at(stamp), scan_at(stamp)}, {false, true, k < 10});
  }
  const slam::LidarSetup base{"top", sim::lidar_model("RS-LiDAR-16"), SE3::identity()};
  const slam::LidarSetup lidar{"right", sim::lidar_model("RS-LiDAR-16"), SE3::identity()};
  const pipelines::RefineConfig refine;
  // Frames 2-11 are kept; the first candidate frame from 0 on is 5: local frames 0-6 are frames 5-11.
  const auto from_start = history.inputs(0, base, lidar, 1, refine);
  ASSERT_TRUE(from_start.has_value());
  EXPECT_EQ(from_start->first_frame, 5U);
  ASSERT_EQ(from_start->base.trajectory().stamps.size(), 7U);
  EXPECT_DOUBLE_EQ(from_start->base.trajectory().stamps[0], 0.5);
  ASSERT_EQ(from_start->target.overlap_points.size(), 7U);
  for (std::size_t k = 0; k < 7; ++k) EXPECT_EQ(from_start->target.overlap_points[k].has_value(), k % kStep == 0) << k;
  const std::optional<Scan> candidate = from_start->target.read_scan(5);  // frame 10
  ASSERT_TRUE(candidate.has_value());
  EXPECT_DOUBLE_EQ(candidate->stamp, 1.0);
  EXPECT_FALSE(from_start->target.read_scan(1).has_value()) << "frame 6 is no candidate frame: its scan is not kept";
  // LiDAR 2 was kept only before frame 10.
  const auto third = history.inputs(0, base, lidar, 2, refine);
  ASSERT_TRUE(third.has_value());
  EXPECT_TRUE(third->target.overlap_points[0].has_value());
  EXPECT_FALSE(third->target.overlap_points[5].has_value());
  // From frame 6 on the first candidate is 10 (two frames); from 11 on there is none.
  const auto late = history.inputs(6, base, lidar, 1, refine);
  ASSERT_TRUE(late.has_value());
  EXPECT_EQ(late->first_frame, 10U);
  EXPECT_FALSE(history.inputs(11, base, lidar, 1, refine).has_value());
  history.clear();
  EXPECT_TRUE(history.empty());
}

}  // namespace
}  // namespace mlidar::test
