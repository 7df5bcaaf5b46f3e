// Odometry on simulated scans with a known motion between them.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>

#include "mlidar/sim/acquisition.hpp"
#include "mlidar/sim/rig.hpp"
#include "mlidar/sim/scenes.hpp"
#include "mlidar/sim/trajectory.hpp"
#include "mlidar/slam/odometry.hpp"
#include "pose_error.hpp"

namespace mlidar::slam {
namespace {

struct TwoFrames {
  std::vector<LidarSetup> lidars;
  Frame first, second;
};

/// Two frames of `rig` standing still at T0 and at T0 * motion (no distortion),
/// seeded; noise_sigma < 0 keeps the models' datasheet range noise. The rig
/// jumps between the frames, which no constant velocity explains, so the
/// scans carry no point times (as already deskewed clouds): nothing is deskewed.
TwoFrames simulate_pair(const std::string& rig_name, const std::string& scene_name, const SE3& motion, double noise_sigma = -1.0,
                        std::uint64_t scene_seed = 11) {
  sim::SimRig rig = sim::named_rig(rig_name);
  if (noise_sigma >= 0.0)
    for (auto& lidar : rig.lidars) lidar.model.range_noise_sigma = noise_sigma;
  const SE3 T0(so3_exp(Vec3(0, 0, 0.3)), Vec3(2.0, 1.0, rig.base_height));
  const SE3 T1 = T0 * motion;
  const std::vector<Vec3> path = {T0.translation(), T1.translation()};
  const sim::Scene scene = sim::make_scene(scene_name, scene_seed, path);
  TwoFrames out;
  out.first.stamp = 0.0;
  out.second.stamp = 0.1;
  for (std::size_t i = 0; i < rig.lidars.size(); ++i) {
    const auto& lidar = rig.lidars[i];
    out.lidars.push_back({lidar.name, lidar.model, lidar.T_base_lidar});
    Scan first = sim::simulate_sweep(scene, lidar, sim::SimTrajectory::stationary(T0), 0.0, sim::sweep_seed(1, 0, i)).scan;
    Scan second = sim::simulate_sweep(scene, lidar, sim::SimTrajectory::stationary(T1), 0.1, sim::sweep_seed(1, 1, i)).scan;
    first.time.clear();
    second.time.clear();
    out.first.scans.push_back(std::move(first));
    out.second.scans.push_back(std::move(second));
  }
  return out;
}

using test::rotation_angle_deg;

TEST(Odometry, RecoversAKnownMotionBetweenTwoScans) {
  // A 64-beam scan at the datasheet's range noise, five scenes. The map is one
  // scan, so its density bounds the accuracy: with a 16-beam VLP-16 the same
  // five scenes give 0.5-2.4 cm / 0.02-0.32 deg (measured; scene 2 worst).
  const SE3 motion(so3_exp(Vec3(0.01, -0.005, 0.05)), Vec3(0.6, 0.15, 0.02));
  for (const std::uint64_t scene_seed : {1, 2, 3, 4, 11}) {
    SCOPED_TRACE(scene_seed);
    const TwoFrames data = simulate_pair("single-hdl64", "campus", motion, -1.0, scene_seed);
    Odometry odometry({}, data.lidars);
    const FrameResult first = odometry.process(data.first);
    EXPECT_TRUE(first.T_world_base.log().isZero());
    const FrameResult second = odometry.process(data.second);
    const SE3 error = motion.inverse() * second.T_world_base;
    EXPECT_LT(error.translation().norm(), 0.01);
    EXPECT_LT(rotation_angle_deg(error), 0.05);
    EXPECT_FALSE(second.lost());
    EXPECT_FALSE(second.registration.degenerate);
    EXPECT_GT(second.registration.eigenvalues(0), 0.0);
  }
}

TEST(Odometry, UsesBothLidarsOfATwoLidarRig) {
  const SE3 motion(so3_exp(Vec3(0.0, 0.0, -0.08)), Vec3(0.5, -0.2, 0.0));
  const TwoFrames data = simulate_pair("rhd", "campus", motion, 0.005);
  Odometry odometry({}, data.lidars);
  odometry.process(data.first);
  const FrameResult second = odometry.process(data.second);
  const SE3 error = motion.inverse() * second.T_world_base;
  EXPECT_LT(error.translation().norm(), 0.01);
  EXPECT_LT(rotation_angle_deg(error), 0.05);
  EXPECT_GT(second.plane_features, 0u);
}

TEST(Odometry, ReusedCorrespondencesMatchSearchingEveryIterationAndResidualsSplitPerLidar) {
  // rematch_distance_m reuses a feature's map fit while it moves < 2 cm: the
  // pose must agree with a search every iteration (rematch 0) well inside both
  // errors' bound (1 cm, as UsesBothLidarsOfATwoLidarRig; measured 2.0 mm apart on
  // this one-scan map).
  const SE3 motion(so3_exp(Vec3(0.0, 0.0, -0.08)), Vec3(0.5, -0.2, 0.0));
  const TwoFrames data = simulate_pair("rhd", "campus", motion, 0.005);
  OdometryConfig every_iteration;
  every_iteration.registration.rematch_distance_m = 0.0;
  Odometry reference(every_iteration, data.lidars);
  Odometry reusing({}, data.lidars);
  const FrameResult first = reusing.process(data.first);
  reference.process(data.first);
  const FrameResult expected = reference.process(data.second);
  const FrameResult second = reusing.process(data.second);
  const SE3 difference = expected.T_world_base.inverse() * second.T_world_base;
  EXPECT_LT(difference.translation().norm(), 0.005);
  EXPECT_LT(rotation_angle_deg(difference), 0.02);
  EXPECT_LT((motion.inverse() * second.T_world_base).translation().norm(), 0.01);
  // One residual per query; finite exactly for the matches; per-LiDAR means weighted back give the overall mean.
  const RegistrationResult& registration = second.registration;
  ASSERT_EQ(registration.residuals_m.size(), registration.queries);
  std::size_t finite = 0;
  for (const float r : registration.residuals_m) finite += std::isfinite(r) ? 1U : 0U;
  EXPECT_EQ(finite, registration.plane_matches + registration.edge_matches);
  ASSERT_EQ(second.lidar_mean_residual_m.size(), data.lidars.size());
  for (const double mean : second.lidar_mean_residual_m) {
    EXPECT_TRUE(std::isfinite(mean));
    EXPECT_GE(mean, 0.0);
    EXPECT_LT(mean, 0.05);
  }
  for (const double mean : first.lidar_mean_residual_m) EXPECT_TRUE(std::isnan(mean));
}

TEST(Odometry, SurvivesALargeTurnByRetryingYaw) {
  // The wider BALM sequence turns up to 48 deg between keyframes.
  for (const double yaw_deg : {48.0, -48.0}) {
    SCOPED_TRACE(yaw_deg);
    const SE3 motion(so3_exp(Vec3(0.0, 0.0, yaw_deg * std::numbers::pi / 180.0)), Vec3(0.3, 0.0, 0.0));
    const TwoFrames data = simulate_pair("single-vlp16", "campus", motion, 0.005);
    OdometryConfig config;
    config.initial_threshold_m = 1.0;
    Odometry odometry(config, data.lidars);
    odometry.process(data.first);
    const FrameResult second = odometry.process(data.second);
    const SE3 error = motion.inverse() * second.T_world_base;
    EXPECT_TRUE(second.retried);
    EXPECT_FALSE(second.lost());
    EXPECT_LT(error.translation().norm(), 0.02);
    EXPECT_LT(rotation_angle_deg(error), 0.1);
  }
}

TEST(Odometry, TurnsBeyondTheRetriesAreFlaggedOrRight) {
  // No retry starts near 120 or 180 deg: the frame must come out lost, or
  // registered correctly, never silently wrong (> 0.2 m or > 2 deg off); a lost
  // frame keeps the prediction (here the first frame's pose, identity).
  // The same set-up with a turn the registration (10 deg) or its yaw retries
  // (30 deg) cover must be registered, not lost: "lost" is allowed only for
  // the hard turns. Measured: 10 and 30 deg within 2.5 mm / 0.011 deg (30 deg
  // retried); 120 and 180 deg lost (match ratio 0.41, 0.35).
  struct Turn {
    double yaw_deg;
    bool hard;
  };
  for (const Turn turn : {Turn{10.0, false}, Turn{30.0, false}, Turn{120.0, true}, Turn{180.0, true}}) {
    SCOPED_TRACE(turn.yaw_deg);
    const SE3 motion(so3_exp(Vec3(0.0, 0.0, turn.yaw_deg * std::numbers::pi / 180.0)), Vec3(0.3, 0.0, 0.0));
    const TwoFrames data = simulate_pair("single-vlp16", "campus", motion, 0.005);
    Odometry odometry({}, data.lidars);
    odometry.process(data.first);
    const FrameResult second = odometry.process(data.second);
    const SE3 error = motion.inverse() * second.T_world_base;
    const bool right = error.translation().norm() < 0.2 && rotation_angle_deg(error) < 2.0;
    EXPECT_TRUE(second.lost() || right) << "error " << error.translation().norm() << " m, " << rotation_angle_deg(error) << " deg";
    if (!turn.hard) {
      EXPECT_FALSE(second.lost()) << "match ratio " << second.registration.match_ratio() << ", mean residual "
                                  << second.registration.mean_residual_m << " m";
      EXPECT_LT(error.translation().norm(), 0.02);
      EXPECT_LT(rotation_angle_deg(error), 0.1);
    } else if (second.lost()) {
      EXPECT_LT(second.T_world_base.log().norm(), 1e-9) << "a lost frame keeps the prediction";
    }
  }
}

TEST(Odometry, FlagsTheCorridorAsDegenerate) {
  const SE3 motion(Quat::Identity(), Vec3(0.15, 0.0, 0.0));
  const TwoFrames data = simulate_pair("single-vlp16", "corridor", motion);
  Odometry odometry({}, data.lidars);
  odometry.process(data.first);
  const FrameResult second = odometry.process(data.second);
  EXPECT_TRUE(second.registration.degenerate);
  EXPECT_LT(second.registration.translation_observability, RegistrationConfig{}.degeneracy_threshold);
}

/// Frames of `rig` driving the `vehicle` trajectory (3.7-7.5 m/s) through
/// the campus, every sweep distorted by the motion, with the ground truth
/// T_world_base at each stamp (world = base at the first stamp).
struct Drive {
  std::vector<LidarSetup> lidars;
  std::vector<Frame> frames;
  std::vector<SE3> truth;
};

Drive simulate_drive(const std::string& rig_name, int frames, const std::string& trajectory_name = "vehicle", bool range_noise = true,
                     const std::string& scene_name = "campus", std::uint64_t seed = 3, int scene_frames = 0) {
  sim::SimRig rig = sim::named_rig(rig_name);
  if (!range_noise)
    for (auto& lidar : rig.lidars) lidar.model.range_noise_sigma = 0.0;
  const sim::SimTrajectory trajectory = sim::SimTrajectory::named(trajectory_name, rig.base_height);
  const double period = rig.frame_period();
  std::vector<Vec3> path;
  // The scene is laid out along the path of scene_frames (0: frames), as `simulate drive` lays it along the whole drive.
  for (int k = 0; k <= std::max(frames, scene_frames); ++k) path.push_back(trajectory.T_world_base(k * period).translation());
  const sim::Scene scene = sim::make_scene(scene_name, seed, path);
  Drive out;
  for (const auto& lidar : rig.lidars) out.lidars.push_back({lidar.name, lidar.model, lidar.T_base_lidar});
  const SE3 T_first_world = trajectory.T_world_base(0.0).inverse();
  for (int k = 0; k < frames; ++k) {
    Frame frame;
    frame.stamp = k * period;
    for (std::size_t i = 0; i < rig.lidars.size(); ++i)
      frame.scans.push_back(
          sim::simulate_sweep(scene, rig.lidars[i], trajectory, frame.stamp, sim::sweep_seed(seed, static_cast<std::uint64_t>(k), i)).scan);
    out.truth.push_back(T_first_world * trajectory.T_world_base(frame.stamp));
    out.frames.push_back(std::move(frame));
  }
  return out;
}

// Regression: deskewing to the frame stamp with a velocity taken from the
// stamp poses fed each pose error back into the next velocity (a period-2
// oscillation: 0.75, 0.30, 1.03, 0.28 m steps at 7.5 m/s) and the first,
// undeskewed frames biased the map by ~0.4 m: metres off within 12 frames.
/// The largest translation and rotation error of the poses added.
struct WorstError {
  double m = 0.0;
  double deg = 0.0;
  void add(const SE3& truth, const SE3& estimate) {
    const SE3 error = truth.inverse() * estimate;
    m = std::max(m, error.translation().norm());
    deg = std::max(deg, rotation_angle_deg(error));
  }
};

/// The drive through a default odometry: every frame must not be lost, `check(k, result)` says what else of frame k.
template <typename Check>
WorstError follow_drive(const Drive& drive, Check check) {
  Odometry odometry({}, drive.lidars);
  WorstError worst;
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    const FrameResult result = odometry.process(drive.frames[k]);
    worst.add(drive.truth[k], result.T_world_base);
    EXPECT_FALSE(result.lost()) << "frame " << k;
    check(k, result);
  }
  return worst;
}

TEST(Odometry, FollowsADrivingRigWhoseSweepsAreDistortedByTheMotion) {
  const WorstError worst = follow_drive(simulate_drive("rv", 12), [](std::size_t k, const FrameResult& result) {
    EXPECT_FALSE(result.registration.degenerate) << "frame " << k << ": campus is not a corridor";
  });
  EXPECT_LT(worst.m, 0.1);
  EXPECT_LT(worst.deg, 0.2);
}

/// `drive` with its LiDAR `lidar` alone.
Drive one_lidar(Drive drive, std::size_t lidar) {
  drive.lidars = {drive.lidars[lidar]};
  for (Frame& frame : drive.frames) frame.scans = {frame.scans[lidar]};
  return drive;
}

/// A gap in the input: the (only) LiDAR's scans from frame `first` to `last` replaced by empty ones.
void blank_scans(Drive& drive, std::size_t first, std::size_t last) {
  for (std::size_t k = first; k <= last; ++k) drive.frames[k].scans[0] = Scan{};
}

// The second frame matches a map of the first sweep alone. A single 16-beam LiDAR at 7.5 m/s matches fewer of its
// features there than later (a feature between the first sweep's rings has too few neighbours for a plane); judged
// by the later frames' share it was lost, the velocity never became known, and so was every later frame.
TEST(Odometry, ASingleSixteenBeamLidarAtSpeedIsNotLostAtItsSecondFrame) {
  // The top RS-LiDAR-16 alone, in the scene of `simulate drive --frames 300 --seed 2`.
  const Drive drive = one_lidar(simulate_drive("rv", 6, "vehicle", true, "campus", 2, 300), 0);
  const WorstError worst = follow_drive(drive, [](std::size_t k, const FrameResult& result) {
    if (k == 1) {
      EXPECT_LT(result.registration.match_ratio(), TrustConfig{}.min_match_ratio) << "the case this test is about";
    }
  });
  EXPECT_LT(worst.m, 0.1);
  EXPECT_LT(worst.deg, 0.2);
}

/// A default configuration that never starts a new map.
OdometryConfig without_restarts() {
  OdometryConfig never;
  never.restart_after_lost = 0;
  never.restart_after_suspect = 0;
  return never;
}

/// Each frame's result of a default odometry over `drive`. At most one frame may start a new map (the first with
/// map_restarted, also returned), and every frame after it must be within 5 cm / 0.2 deg of the truth's motion from
/// that frame: the motion after a restart is measured again, only the restart frame's offset is unknown.
std::pair<std::vector<FrameResult>, std::optional<std::size_t>> follow_drive_through_one_restart(const Drive& drive) {
  Odometry odometry({}, drive.lidars);
  std::vector<FrameResult> results;
  std::optional<std::size_t> restart;
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    results.push_back(odometry.process(drive.frames[k]));
    const FrameResult& result = results.back();
    if (result.map_restarted) {
      EXPECT_FALSE(restart) << "one restart, frame " << k;
      restart = k;
    } else if (restart) {
      const SE3 truth = drive.truth[*restart].inverse() * drive.truth[k];
      const SE3 error = truth.inverse() * (results[*restart].T_world_base.inverse() * result.T_world_base);
      EXPECT_LT(error.translation().norm(), 0.05) << "frame " << k;
      EXPECT_LT(rotation_angle_deg(error), 0.2) << "frame " << k;
    }
  }
  return {results, restart};
}

// A gap in the input right after the first frame (no scan for 0.8 s at 7.5 m/s): the velocity was never measured, so
// the prediction stays at the start, 6 m behind, where the registrations fail (checked with restarts off: every
// later frame lost). After restart_after_lost failed registrations the next frame starts a new map at its predicted
// pose; from there the relative motion is measured again, and only the restart frame's offset is unknown.
TEST(Odometry, FailedRegistrationsInARowStartANewMapAndTheMotionAfterItIsMeasuredAgain) {
  constexpr std::size_t kFrames = 24, kGap = 8;
  Drive drive = one_lidar(simulate_drive("rv", kFrames, "vehicle", true, "campus", 2, 300), 0);  // the top RS-LiDAR-16 alone
  blank_scans(drive, 1, kGap);

  Odometry stuck(without_restarts(), drive.lidars);
  std::size_t lost_after_gap = 0;
  for (std::size_t k = 0; k < kFrames; ++k) lost_after_gap += stuck.process(drive.frames[k]).lost() && k > kGap ? 1 : 0;
  EXPECT_EQ(lost_after_gap, kFrames - kGap - 1) << "the case this test is about";

  const auto [results, restart] = follow_drive_through_one_restart(drive);
  ASSERT_TRUE(restart);
  for (std::size_t k = 0; k < kFrames; ++k) EXPECT_EQ(results[k].lost(), k > 0 && (k <= kGap || k <= *restart)) << "frame " << k;
  EXPECT_EQ(*restart, kGap + 1 + OdometryConfig{}.restart_after_lost);  // 5 failed registrations, then the restart
}

/// The top RS-LiDAR-16 of `simulate drive --rig rv --frames 100 --seed SEED` (campus, vehicle: 3.7-7.5 m/s) alone for
/// `frames` frames, without scans from gap_first to gap_last, through a default odometry: the frames in the gap must
/// be lost, every other one trusted, and each pair from the first frame after the gap on within `max_m` and 0.2 deg of
/// the truth's motion.
void follow_drive_across_a_gap(std::uint64_t seed, std::size_t frames, std::size_t gap_first, std::size_t gap_last, double max_m) {
  Drive drive = one_lidar(simulate_drive("rv", static_cast<int>(frames), "vehicle", true, "campus", seed, 100), 0);
  blank_scans(drive, gap_first, gap_last);

  Odometry odometry({}, drive.lidars);
  std::vector<SE3> estimates;
  for (std::size_t k = 0; k < frames; ++k) {
    const FrameResult result = odometry.process(drive.frames[k]);
    EXPECT_EQ(result.lost(), k >= gap_first && k <= gap_last) << "frame " << k;
    EXPECT_FALSE(result.suspect()) << "frame " << k;
    estimates.push_back(result.T_world_base);
  }
  for (std::size_t k = gap_last + 1; k + 1 < frames; ++k) {
    const SE3 truth = drive.truth[k].inverse() * drive.truth[k + 1];
    const SE3 error = truth.inverse() * (estimates[k].inverse() * estimates[k + 1]);
    EXPECT_LT(error.translation().norm(), max_m) << "frames " << k << "-" << k + 1;
    EXPECT_LT(rotation_angle_deg(error), 0.2) << "frames " << k << "-" << k + 1;
  }
}

// A gap in the middle of a drive: the frames in it are lost, their poses predictions with the velocity from before.
// The velocity after the gap was measured from the gap's last prediction to the first registered frame, which put
// the prediction's whole error over the gap into 0.1 s: the next frame was deskewed and predicted with it. After
// 0.8 s (seed 1) its motion was 7 cm off, trusted. The velocity starts at the last registered pose instead
// (Odometry::velocity_anchor).
TEST(Odometry, TheMotionAfterAGapInTheMiddleOfADriveIsMeasuredAsBeforeIt) { follow_drive_across_a_gap(1, 44, 30, 37, 0.03); }

// After 2 s (seed 3) the frames after the gap were ambiguous or degenerate, then trusted while sliding 3.5 m a frame
// too far along the road, frame after frame (ATE 18 m over 100 frames).
TEST(Odometry, AFrameAfterATwoSecondGapDoesNotSendTheDriveAway) { follow_drive_across_a_gap(3, 60, 30, 49, 0.05); }

// The right RS-LiDAR-16 alone (rolled 15 deg towards the ground on its side of the road) after 2 s without scans: its
// first frames after the gap fit the map only where the ground and a few walls pin them, degenerate, and went wrong
// (13 m off, flagged). A degenerate registration that stays near its prediction was trusted, but that prediction
// came from the wrong frames: 5 pairs 0.2-3.4 m / up to 61 deg off were trusted. A degenerate registration is now
// trusted only when the frame before it was.
TEST(Odometry, ADegenerateFrameAfterAFlaggedOneIsNotTrusted) {
  constexpr std::size_t kFrames = 56, kGapFirst = 30, kGapLast = 49;
  const Drive rig = simulate_drive("rv", kFrames, "vehicle", true, "campus", 3, 100);  // `simulate drive --frames 100 --seed 3`
  const std::size_t right = 3;
  ASSERT_EQ(rig.lidars[right].name, "right");
  Drive drive = one_lidar(rig, right);
  blank_scans(drive, kGapFirst, kGapLast);

  Odometry odometry({}, drive.lidars);
  std::vector<FrameResult> results;
  for (std::size_t k = 0; k < kFrames; ++k) results.push_back(odometry.process(drive.frames[k]));
  std::size_t degenerate_after_the_gap = 0;
  for (std::size_t k = kGapLast + 1; k < kFrames; ++k) degenerate_after_the_gap += results[k].registration.degenerate ? 1 : 0;
  EXPECT_GT(degenerate_after_the_gap, 3U) << "the case this test is about";
  for (std::size_t k = 0; k + 1 < kFrames; ++k) {
    if (results[k].flagged() || results[k + 1].flagged()) continue;
    const SE3 truth = drive.truth[k].inverse() * drive.truth[k + 1];
    const SE3 error = truth.inverse() * (results[k].T_world_base.inverse() * results[k + 1].T_world_base);
    EXPECT_LT(error.translation().norm(), 0.05) << "frames " << k << "-" << k + 1 << ", neither flagged";
    EXPECT_LT(rotation_angle_deg(error), 0.5) << "frames " << k << "-" << k + 1 << ", neither flagged";
  }
}

// The same gap, followed further: only trusted frames enter the map, and every frame after the gap registered
// degenerate or ambiguous against the map left 20 m behind, so nothing was ever trusted again (checked with
// restarts off: every frame suspect to the end, the pairs off by metres). After restart_after_suspect
// untrusted frames in a row the next one starts a new map, and the motion after it is measured again.
TEST(Odometry, UntrustedFramesInARowStartANewMapAndTheMotionAfterItIsMeasuredAgain) {
  constexpr std::size_t kFrames = 72, kGapFirst = 30, kGapLast = 49;
  const Drive rig = simulate_drive("rv", kFrames, "vehicle", true, "campus", 3, 100);
  Drive drive = one_lidar(rig, 3);  // right
  blank_scans(drive, kGapFirst, kGapLast);

  Odometry stuck(without_restarts(), drive.lidars);
  std::size_t flagged_after_gap = 0;
  for (std::size_t k = 0; k < kFrames; ++k) flagged_after_gap += stuck.process(drive.frames[k]).flagged() && k > kGapLast ? 1 : 0;
  EXPECT_EQ(flagged_after_gap, kFrames - kGapLast - 1) << "the case this test is about";

  const auto [results, restart] = follow_drive_through_one_restart(drive);
  ASSERT_TRUE(restart);
  for (std::size_t k = *restart + 1; k < kFrames; ++k) EXPECT_EQ(results[k].trust, Trust::kTrusted) << "frame " << k;
  EXPECT_EQ(*restart, kGapLast + 1 + OdometryConfig{}.restart_after_suspect);  // 10 untrusted frames, then the restart
}

/// The drive's LiDARs with LiDAR 1's extrinsic turned 10 deg about each axis and moved 0.1 m along each (Table 4.6's
/// injected perturbation), its doubt given as that 1-sigma times alpha = 10 (eq 4.24, left perturbation).
std::vector<LidarSetup> with_injected_perturbation(std::vector<LidarSetup> lidars) {
  LidarSetup& perturbed = lidars.at(1);
  const double angle = deg_to_rad(10.0);
  perturbed.T_base_lidar = SE3(perturbed.T_base_lidar.rotation() * so3_exp(Vec3(angle, angle, angle)),
                               perturbed.T_base_lidar.translation() + Vec3(0.1, 0.1, 0.1));
  Vec6 variances;
  variances << 0.01, 0.01, 0.01, angle * angle, angle * angle, angle * angle;
  perturbed.extrinsic_covariance = 10.0 * Mat6(variances.asDiagonal());
  return lidars;
}

OdometryConfig uncertainty_aware(bool on) {
  OdometryConfig config;
  config.uncertainty.enabled = on;
  return config;
}

// Thesis sec 4.8 / Table 4.6: an auxiliary LiDAR with a wrong extrinsic drags the plain odometry off; given its
// doubt, uncertainty-aware mapping weights it down and keeps its points out of the map, and follows the drive as
// with the true extrinsics.
TEST(Odometry, UncertaintyAwareMappingFollowsTheDriveDespiteAWrongExtrinsic) {
  const Drive drive = simulate_drive("rv", 12);
  const std::vector<LidarSetup> perturbed = with_injected_perturbation(drive.lidars);
  WorstError plain_worst, aware_worst;
  Odometry plain(uncertainty_aware(false), perturbed), aware(uncertainty_aware(true), perturbed);
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    plain_worst.add(drive.truth[k], plain.process(drive.frames[k]).T_world_base);
    const FrameResult result = aware.process(drive.frames[k]);
    aware_worst.add(drive.truth[k], result.T_world_base);
    EXPECT_FALSE(result.flagged()) << "frame " << k;
    // The doubtful LiDAR's features are too uncertain for the registration and the map, the certain ones' are not.
    ASSERT_EQ(result.lidar_uncertain.size(), 4u);
    EXPECT_GE(result.lidar_uncertain[1], 9 * (result.lidar_uncertain[1] + result.lidar_features[1]) / 10) << "frame " << k;
    EXPECT_EQ(result.lidar_uncertain[0], 0u) << "frame " << k;
    if (k < 2) continue;  // the first two frames are mapped again at frame 1 (no report)
    ASSERT_TRUE(result.mapping) << "frame " << k;
    EXPECT_LT(result.mapping->dropped_uncertain, result.mapping->features / 10) << "frame " << k;
  }
  // Measured: plain 0.100 m / 0.064 deg, aware 0.0045 m / 0.021 deg.
  EXPECT_GT(plain_worst.m, 0.05);
  EXPECT_LT(aware_worst.m, 0.02);
  EXPECT_LT(aware_worst.deg, 0.1);
}

OdometryConfig selecting(SelectionMethod method, double ratio = 0.2) {
  OdometryConfig config;
  config.registration.selection.method = method;
  config.registration.selection.ratio = ratio;
  config.registration.selection.adaptive = false;
  return config;
}

// Thesis Ch. 5: the registration on the greedy fifth of the features follows
// the distorted drive as the full set does (same bounds as above), every LiDAR
// keeps features, and far fewer features are searched than the frame has.
TEST(Odometry, GreedySelectionFollowsTheDriveWithAFifthOfTheFeatures) {
  const Drive drive = simulate_drive("rv", 12);
  Odometry odometry(selecting(SelectionMethod::kGreedy), drive.lidars);
  WorstError worst;
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    const FrameResult result = odometry.process(drive.frames[k]);
    worst.add(drive.truth[k], result.T_world_base);
    EXPECT_FALSE(result.flagged()) << "frame " << k;
    if (k == 0) continue;  // the first frame builds the map
    ASSERT_TRUE(result.registration.selection) << "frame " << k;
    const SelectionReport& s = *result.registration.selection;
    const std::size_t features = result.edge_features + result.plane_features;
    EXPECT_EQ(s.budget, static_cast<std::size_t>(std::ceil(0.2 * static_cast<double>(features))));
    EXPECT_EQ(s.chosen.size(), s.budget);
    EXPECT_LT(s.screened, features * 3 / 4) << "lazy search: only drawn features are searched";
    EXPECT_GT(s.log_det_selected, 0.0);
    ASSERT_EQ(result.lidar_selected.size(), 4u);
    std::size_t sum = 0;
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_GT(result.lidar_selected[i], 0u) << "LiDAR " << i;
      EXPECT_LE(result.lidar_selected[i], result.lidar_features[i]);
      sum += result.lidar_selected[i];
    }
    EXPECT_EQ(sum, s.chosen.size());
    std::size_t with_residual = 0;
    for (const float r : result.registration.residuals_m) with_residual += std::isfinite(r) ? 1U : 0U;
    EXPECT_LE(with_residual, s.chosen.size());  // the others were not registered
    EXPECT_GT(result.registration.match_ratio(), 0.5);
  }
  EXPECT_LT(worst.m, 0.1);
  EXPECT_LT(worst.deg, 0.2);
}

TEST(Odometry, SelectionIsTheSameForTheSameSeedAndGreedyKeepsMoreInformationThanRandom) {
  const Drive drive = simulate_drive("rv", 6);
  Odometry greedy(selecting(SelectionMethod::kGreedy), drive.lidars), again(selecting(SelectionMethod::kGreedy), drive.lidars),
      random(selecting(SelectionMethod::kRandom), drive.lidars);
  double greedy_sum = 0.0, random_sum = 0.0;
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    const FrameResult a = greedy.process(drive.frames[k]), b = again.process(drive.frames[k]), c = random.process(drive.frames[k]);
    EXPECT_EQ(a.T_world_base.matrix(), b.T_world_base.matrix()) << "frame " << k;
    if (k == 0) continue;
    EXPECT_EQ(a.registration.selection->chosen, b.registration.selection->chosen);
    EXPECT_EQ(c.registration.selection->chosen.size(), a.registration.selection->chosen.size());
    greedy_sum += a.registration.selection->log_det_selected;
    random_sum += c.registration.selection->log_det_selected;
  }
  EXPECT_GT(greedy_sum, random_sum + 5.0);  // measured +1.7 per frame on rv campus (300 frames)
}

// The held-out check: features the selection did not use are searched at
// the final pose; where they fit worse than the bound, the registration runs
// again on every feature, and its result is that one's.
TEST(Odometry, ASelectionTheHeldOutFeaturesDisagreeWithFallsBackToEveryFeature) {
  const Drive drive = simulate_drive("rv", 4);
  OdometryConfig strict = selecting(SelectionMethod::kGreedy);
  strict.registration.selection.held_out_residual_ratio = 0.0;  // any residual disagrees
  strict.registration.selection.held_out_residual_floor_m = 0.0;
  Odometry plain({}, drive.lidars), checked(selecting(SelectionMethod::kGreedy), drive.lidars), falling(strict, drive.lidars);
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    const FrameResult a = plain.process(drive.frames[k]), b = checked.process(drive.frames[k]), c = falling.process(drive.frames[k]);
    if (k == 0) continue;
    ASSERT_TRUE(b.registration.selection && c.registration.selection);
    const SelectionReport& agreed = *b.registration.selection;
    EXPECT_FALSE(agreed.fell_back);
    EXPECT_EQ(agreed.held_out, static_cast<std::size_t>(std::ceil(0.25 * static_cast<double>(agreed.chosen.size()))));
    EXPECT_GT(agreed.held_out_matches, agreed.held_out / 2);
    EXPECT_LT(agreed.held_out_mean_residual_m, 1.5 * b.registration.mean_residual_m + 0.01);
    EXPECT_TRUE(c.registration.selection->fell_back);
    EXPECT_EQ(c.T_world_base.matrix(), a.T_world_base.matrix()) << "frame " << k;  // the full registration's result
    EXPECT_EQ(c.registration.match_ratio(), a.registration.match_ratio());
    EXPECT_EQ(c.lidar_selected, c.lidar_features);
  }
}

TEST(Odometry, SelectionOfEveryFeatureIsTheRegistrationWithout) {
  const Drive drive = simulate_drive("rv", 4);
  Odometry plain({}, drive.lidars), all(selecting(SelectionMethod::kGreedy, 1.0), drive.lidars);
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    const FrameResult a = plain.process(drive.frames[k]), b = all.process(drive.frames[k]);
    EXPECT_EQ(a.T_world_base.matrix(), b.T_world_base.matrix()) << "frame " << k;  // bit for bit
    EXPECT_FALSE(b.registration.selection);
  }
}

// A map patch must be wider than the range noise of the LiDARs that built the map
// (plane_min_extent_sigmas of the noisiest one's sigma, the configured one where the
// model gives none), and follows the LiDARs when they change.
TEST(Odometry, ThePlanePatchWidthFollowsTheNoisiestLidar) {
  LidarModel quiet, noisy, unknown;
  quiet.range_noise_sigma = 0.01;
  noisy.range_noise_sigma = 0.05;
  const LidarSetup a{"a", quiet, SE3::identity()}, b{"b", noisy, SE3::identity()}, c{"c", unknown, SE3::identity()};
  OdometryConfig config;
  config.plane_min_extent_sigmas = 0.5;
  config.uncertainty.range_sigma_m = 0.04;
  Odometry odometry(config, {a, b});
  EXPECT_DOUBLE_EQ(odometry.config().registration.plane_min_extent_m, 0.025);
  odometry.set_lidars({a});
  EXPECT_DOUBLE_EQ(odometry.config().registration.plane_min_extent_m, 0.005);
  odometry.set_lidars({a, c});
  EXPECT_DOUBLE_EQ(odometry.config().registration.plane_min_extent_m, 0.02);
  config.plane_min_extent_sigmas = 0.0;
  EXPECT_EQ(Odometry(config, {a, b}).config().registration.plane_min_extent_m, 0.0);
}

// A plane takes up to plane_neighbors_max map neighbours in frames of range-image
// features and up to voxel_plane_neighbors_max in frames of voxel samples (no
// model and no rows): each setting changes its own kind of frame and not the other.
TEST(Odometry, ThePlaneFitFollowsTheKindOfFeatures) {
  const Drive drive = simulate_drive("rv", 4);
  std::vector<LidarSetup> without_model = drive.lidars;
  for (LidarSetup& lidar : without_model) lidar.model.vertical_angles_deg.clear();
  const auto poses = [&](int plane_max, int voxel_plane_max, const std::vector<LidarSetup>& lidars) {
    OdometryConfig config;
    config.registration.plane_neighbors_max = plane_max;
    config.voxel_plane_neighbors_max = voxel_plane_max;
    config.front_end.recover_rows = false;  // no rows from the ring channel either: voxel samples
    Odometry odometry(config, lidars);
    std::vector<Mat4> out;
    for (const Frame& frame : drive.frames) out.push_back(odometry.process(frame).T_world_base.matrix());
    return out;
  };
  const auto range_image = poses(5, 5, drive.lidars);
  EXPECT_EQ(range_image, poses(5, 8, drive.lidars));  // bit for bit
  EXPECT_NE(range_image, poses(8, 5, drive.lidars));
  const auto voxel_samples = poses(5, 5, without_model);
  EXPECT_EQ(voxel_samples, poses(8, 5, without_model));
  EXPECT_NE(voxel_samples, poses(5, 8, without_model));
}

// The selection chooses by information at the start pose, which the thesis has
// at 10 Hz: frames farther apart than max_frame_gap_s register every feature
// (bit for bit the run without selection), closer ones select.
TEST(Odometry, FramesFartherApartThanTheGapLimitRegisterEveryFeature) {
  const Drive drive = simulate_drive("rv", 7);
  std::vector<Frame> every_third;  // 0.3 s apart
  for (std::size_t k = 0; k < drive.frames.size(); k += 3) every_third.push_back(drive.frames[k]);
  OdometryConfig wide_gap = selecting(SelectionMethod::kGreedy);
  wide_gap.registration.selection.max_frame_gap_s = 0.5;
  Odometry plain({}, drive.lidars), limited(selecting(SelectionMethod::kGreedy), drive.lidars), selecting_all(wide_gap, drive.lidars);
  for (std::size_t k = 0; k < every_third.size(); ++k) {
    const FrameResult a = plain.process(every_third[k]), b = limited.process(every_third[k]), c = selecting_all.process(every_third[k]);
    EXPECT_EQ(a.T_world_base.matrix(), b.T_world_base.matrix()) << "frame " << k;
    EXPECT_FALSE(b.registration.selection) << "frame " << k;
    if (k > 0) {
      EXPECT_TRUE(c.registration.selection) << "frame " << k;
    }
  }
}

// Sec 5.4.4: the full set's information is weaker in the corridor than in the
// open campus (the same rig, motion and map size), and each side of the
// threshold keeps its share of the features.
TEST(Odometry, AdaptiveSelectionKeepsMoreFeaturesInTheCorridor) {
  const SE3 motion(Quat::Identity(), Vec3(0.15, 0.0, 0.0));
  const TwoFrames corridor = simulate_pair("rv", "corridor", motion, 0.005), campus = simulate_pair("rv", "campus", motion, 0.005);
  const auto lambda_of = [](const TwoFrames& data, const OdometryConfig& config) {
    Odometry odometry(config, data.lidars);
    odometry.process(data.first);
    return odometry.process(data.second);
  };
  OdometryConfig config = selecting(SelectionMethod::kGreedy);
  config.registration.selection.adaptive = true;
  const FrameResult in_corridor = lambda_of(corridor, config), on_campus = lambda_of(campus, config);
  ASSERT_TRUE(in_corridor.full_set_degeneracy && on_campus.full_set_degeneracy);
  const Degeneracy a = *in_corridor.full_set_degeneracy, b = *on_campus.full_set_degeneracy;
  std::printf("corridor: log det %.2f, observability %.3f; campus: %.2f, %.3f\n", a.log_det, a.translation_observability, b.log_det,
              b.translation_observability);
  EXPECT_LT(a.log_det + 5.0, b.log_det);  // measured 48.2 and 59.2
  EXPECT_LT(a.translation_observability, 0.05);
  EXPECT_GT(b.translation_observability, 0.2);
  EXPECT_TRUE(in_corridor.degenerate_scene);
  EXPECT_FALSE(on_campus.degenerate_scene);
  EXPECT_EQ(in_corridor.registration.selection->budget,
            static_cast<std::size_t>(std::ceil(0.8 * static_cast<double>(in_corridor.edge_features + in_corridor.plane_features))));
  EXPECT_EQ(on_campus.registration.selection->budget,
            static_cast<std::size_t>(std::ceil(0.2 * static_cast<double>(on_campus.edge_features + on_campus.plane_features))));
}

// The default threshold on short drives of the rv rig: the corridor is
// degenerate wherever it is judged, the campus mostly not (over 300 frames of
// rv/campus seed 3, 1 of 29 evaluations fell below 0.1: 0.046, at a frame
// where the ground dominates; docs/benchmarks.md "Feature selection").
TEST(Odometry, DefaultDegeneracyThresholdSeparatesTheCorridorDriveFromTheCampus) {
  OdometryConfig config = selecting(SelectionMethod::kGreedy);
  config.registration.selection.adaptive = true;
  config.registration.selection.degeneracy_interval_s = 0.2;
  for (const bool in_corridor : {true, false}) {
    const Drive drive = in_corridor ? simulate_drive("rv", 12, "corridor", true, "corridor") : simulate_drive("rv", 12);
    Odometry odometry(config, drive.lidars);
    int evaluated = 0, degenerate = 0;
    for (const Frame& frame : drive.frames) {
      const FrameResult result = odometry.process(frame);
      if (!result.full_set_degeneracy) continue;
      ++evaluated;
      degenerate += result.degenerate_scene ? 1 : 0;
      std::printf("%s: observability %.3f\n", in_corridor ? "corridor" : "campus", result.full_set_degeneracy->translation_observability);
    }
    EXPECT_GE(evaluated, 4);
    if (in_corridor) {
      EXPECT_EQ(degenerate, evaluated);
    } else {
      EXPECT_LT(2 * degenerate, evaluated);
    }
  }
}

// refine_deskew: the frame deskewed again with the velocity its registration
// measured and registered once more follows the drive at least as well. 20
// frames: over 12 the summed errors (3 cm) differ by a few millimetres
// either way with the map's plane fit (2026-12-07: 7 % against refined).
TEST(Odometry, RefinedDeskewFollowsTheDriveAtLeastAsWell) {
  constexpr int kFrames = 20;
  const Drive drive = simulate_drive("rv", kFrames);
  OdometryConfig refined_config;
  refined_config.refine_deskew = true;
  Odometry plain({}, drive.lidars), refined(refined_config, drive.lidars);
  double plain_sum_m = 0.0, refined_sum_m = 0.0, refined_worst_deg = 0.0;
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    plain_sum_m += (drive.truth[k].inverse() * plain.process(drive.frames[k]).T_world_base).translation().norm();
    const FrameResult result = refined.process(drive.frames[k]);
    EXPECT_FALSE(result.lost()) << "frame " << k;
    const SE3 error = drive.truth[k].inverse() * result.T_world_base;
    refined_sum_m += error.translation().norm();
    refined_worst_deg = std::max(refined_worst_deg, rotation_angle_deg(error));
  }
  std::printf("mean translation error: plain %.4f m, refined %.4f m\n", plain_sum_m / kFrames, refined_sum_m / kFrames);
  EXPECT_LE(refined_sum_m, 1.05 * plain_sum_m);
  EXPECT_LT(refined_sum_m / kFrames, 0.05);
  EXPECT_LT(refined_worst_deg, 0.2);
}

// deskew_in_registration: features deskewed again between iterations with the
// velocity the estimate implies (MotionDeskew) follow a handheld walk (its
// velocity changes from sweep to sweep) better than with the prediction's
// velocity, a frame late. Without range noise, so that the sweep distortion
// is what is left to get wrong.
TEST(Odometry, DeskewInsideTheRegistrationFollowsAHandheldWalkBetter) {
  const Drive drive = simulate_drive("rhd", 20, "handheld", false);  // no range noise: the deskew is the error left
  OdometryConfig plain_config, in_loop_config;
  plain_config.deskew_in_registration = false;
  in_loop_config.deskew_in_registration = true;
  Odometry plain(plain_config, drive.lidars), in_loop(in_loop_config, drive.lidars);
  double plain_sum_m = 0.0, in_loop_sum_m = 0.0, in_loop_worst_deg = 0.0;
  for (std::size_t k = 0; k < drive.frames.size(); ++k) {
    plain_sum_m += (drive.truth[k].inverse() * plain.process(drive.frames[k]).T_world_base).translation().norm();
    const FrameResult result = in_loop.process(drive.frames[k]);
    EXPECT_FALSE(result.lost()) << "frame " << k;
    EXPECT_EQ(result.registration.velocity_used.has_value(), k >= 2) << "frame " << k;  // from the third frame (two centroids)
    const SE3 error = drive.truth[k].inverse() * result.T_world_base;
    in_loop_sum_m += error.translation().norm();
    in_loop_worst_deg = std::max(in_loop_worst_deg, rotation_angle_deg(error));
  }
  std::printf("mean translation error: plain %.4f m, deskew in registration %.4f m; worst rotation %.3f deg\n", plain_sum_m / 20.0,
              in_loop_sum_m / 20.0, in_loop_worst_deg);
  EXPECT_LT(in_loop_sum_m, plain_sum_m);
  EXPECT_LT(in_loop_worst_deg, 0.5);
}

}  // namespace
}  // namespace mlidar::slam
