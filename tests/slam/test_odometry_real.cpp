// Odometry on real data: BALM's Ouster keyframes full20..full119 (0.5 s apart,
// already deskewed, no ring or time fields, so the model-free front end runs)
// against the authors' reference poses (LiDAR-inertial bundle adjustment, ~2 cm
// noise). Checks every consecutive pair: none off (> 0.1 m or > 1-2 deg)
// unless its later frame is flagged suspect or lost, and mean relative errors
// within the bounds measured with margin.
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "mlidar/eval/trajectory_metrics.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/point_table.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/slam/odometry.hpp"
#include "pose_error.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

constexpr int kFirstFrame = 20;  // the reference poses start at frame 0
// full20 .. full49, all 30 keyframes. Measured 2026-11-23: ATE 0.0072 m, mean
// pair error 0.0052 m / 0.053 deg, worst pair 0.012 m / 0.13 deg. Pairs 45-46
// and 48-49 turn 21 and 11 deg: before registrations had to be tight to be
// trusted (TrustConfig::max_mean_residual_m) they settled 12 deg off.
constexpr int kFrames = 30;

/// Frame k -> k+1 against the reference: E = (T_gt_k^-1 T_gt_k+1)^-1 (T_est_k^-1 T_est_k+1).
struct PairError {
  double translation_m = 0.0;
  double rotation_deg = 0.0;
  bool flagged = false;  ///< the later frame is suspect or lost
};

struct BalmRun {
  std::vector<SE3> gt, est;
  std::vector<PairError> pairs;
  std::vector<bool> suspect_frames;
  std::vector<std::size_t> map_sizes;  ///< plane map points after each frame
  std::vector<int> recovered_rows;     ///< per frame: rows recovered from the keyframe, 0 where it showed none
  int lost = 0;
  int suspect = 0;
  int retried = 0;          ///< frames whose first registration ran the retries
  int full_iterations = 0;  ///< the kept registrations' iterations, summed

  double mean_translation_m() const { return mean([](const PairError& p) { return p.translation_m; }); }
  double mean_rotation_deg() const { return mean([](const PairError& p) { return p.rotation_deg; }); }
  /// Pairs off by more than either bound whose later frame is not flagged.
  int unflagged_beyond(double translation_m, double rotation_deg) const {
    int count = 0;
    for (const PairError& p : pairs) count += !p.flagged && (p.translation_m > translation_m || p.rotation_deg > rotation_deg) ? 1 : 0;
    return count;
  }

 private:
  template <typename Field>
  double mean(Field field) const {
    double sum = 0.0;
    for (const PairError& p : pairs) sum += field(p);
    return sum / static_cast<double>(pairs.size());
  }
};

/// Odometry over the keyframes first, first + step, ... (count of them), `step` x 0.5 s apart.
/// `alter` may change a keyframe's scan (by its BALM index) before it is processed.
BalmRun run_balm(int first, int step, int count, const slam::OdometryConfig& config = {},
                 const std::function<void(int, Scan&)>& alter = {}) {
  const auto folder = shared_data() / "real" / "balm_ouster";
  Trajectory reference = io::read_balm_poses(folder / "alidarPose_0-49.csv");
  for (const StampedPose& pose : io::read_balm_poses(folder / "alidarPose_50-119.csv").poses) reference.poses.push_back(pose);
  EXPECT_GE(reference.size(), static_cast<std::size_t>(first + step * (count - 1) + 1));
  slam::Odometry odometry(config, {{"ouster", LidarModel{}, SE3::identity()}});
  BalmRun run;
  std::vector<bool> flagged;
  for (int k = 0; k < count; ++k) {
    const int index = first + step * k;
    const auto path = folder / "frames" / ("full" + std::to_string(index) + ".pcd");
    Frame frame;
    frame.stamp = 0.5 * step * k;
    frame.scans.push_back(io::to_scan(io::read_cloud(path).table, path.string()));
    frame.scans.back().stamp = frame.stamp;
    if (alter) alter(index, frame.scans.back());
    const slam::FrameResult result = odometry.process(frame);
    run.lost += result.lost() ? 1 : 0;
    run.suspect += result.suspect() ? 1 : 0;
    run.retried += result.retried ? 1 : 0;
    run.full_iterations += result.registration.iterations;
    flagged.push_back(result.flagged());
    run.suspect_frames.push_back(result.suspect());
    run.map_sizes.push_back(odometry.plane_map().points().size());
    run.recovered_rows.push_back(result.lidar_row_source[0] == slam::RowSource::kRecovered ? result.lidar_rows[0] : 0);
    run.est.push_back(result.T_world_base);
    run.gt.push_back(reference.poses[static_cast<std::size_t>(index)].T_world_base);
  }
  for (std::size_t i = 0; i + 1 < run.gt.size(); ++i) {
    const SE3 error = (run.gt[i].inverse() * run.gt[i + 1]).inverse() * (run.est[i].inverse() * run.est[i + 1]);
    run.pairs.push_back({error.translation().norm(), test::rotation_angle_deg(error), flagged[i + 1]});
  }
  return run;
}

double ate_m(const BalmRun& run) {
  const auto alignment = eval::compute_alignment(eval::AlignMode::kSe3, run.gt, run.est, "estimate");
  std::vector<SE3> aligned;
  for (const SE3& T : run.est) aligned.push_back(alignment.apply(T));
  return eval::compute_ate(run.gt, aligned).translation_m.rmse;
}

void print(const char* name, const BalmRun& run) {
  std::cout << name << ": ATE " << ate_m(run) << " m, pair error " << run.mean_translation_m() << " m / " << run.mean_rotation_deg()
            << " deg, " << run.suspect << " suspect, " << run.lost << " lost, " << run.retried << " retried, "
            << run.full_iterations << " iterations\n";
  for (std::size_t i = 0; i < run.pairs.size(); ++i)
    if (run.pairs[i].translation_m > 0.1 || run.pairs[i].rotation_deg > 1.0)
      std::cout << "  pair " << i << ": " << run.pairs[i].translation_m << " m " << run.pairs[i].rotation_deg << " deg"
                << (run.pairs[i].flagged ? " (flagged)" : "") << '\n';
}

TEST(OdometryReal, BalmOusterKeyframesFollowTheReferencePoses) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const BalmRun run = run_balm(kFirstFrame, 1, kFrames);
  print("balm frames 20..49", run);
  // The still keyframes show the sensor's 64 rows and get the range-image
  // front end (row_recovery.hpp); 22 (two sweeps) and the moving ones do not.
  // After 22's refusal 23 takes the voxel samples without a search
  // (recover_rows_max_skip); 24 is searched and recovered again.
  const std::vector<int> first_rows(run.recovered_rows.begin(), run.recovered_rows.begin() + 6);
  EXPECT_EQ(first_rows, (std::vector<int>{64, 64, 0, 0, 64, 64}));
  EXPECT_EQ(run.lost, 0);
  EXPECT_EQ(run.suspect, 0);
  EXPECT_EQ(run.unflagged_beyond(0.2, 2.0), 0);
  EXPECT_LT(run.mean_translation_m(), 0.015);
  EXPECT_LT(run.mean_rotation_deg(), 0.15);
  EXPECT_LT(ate_m(run), 0.02);
}

// Keyframes of voxel samples start their full registration where a coarse
// pass on every 8th feature ended (voxel_coarse_stride): measured 2026-12-07,
// 151 full iterations over these 30 keyframes against 352 from the
// constant-velocity prediction (every one a map search for every feature),
// no frame retried against 1, pair errors 5.4 mm / 0.047 deg against
// 5.1 mm / 0.048 deg.
TEST(OdometryReal, ACoarsePassFirstBringsVoxelFramesCloserToTheirPose) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const BalmRun coarse = run_balm(kFirstFrame, 1, kFrames);
  slam::OdometryConfig direct;
  direct.voxel_coarse_stride = 1;
  const BalmRun full = run_balm(kFirstFrame, 1, kFrames, direct);
  print("balm frames 20..49, coarse pass first", coarse);
  print("balm frames 20..49, every feature from the prediction", full);
  EXPECT_LT(coarse.full_iterations, full.full_iterations / 2);
  EXPECT_LE(coarse.retried, full.retried);
  EXPECT_EQ(coarse.unflagged_beyond(0.1, 1.0), 0);
  EXPECT_LT(coarse.mean_translation_m(), 1.15 * full.mean_translation_m());
  EXPECT_LT(coarse.mean_rotation_deg(), 1.15 * full.mean_rotation_deg());
}

// Frames 50..60, started at 50: keyframe 56 registered from its prediction
// settles 2.5 deg / 0.3 m off with 93 % of its features matched, at a mean |r|
// 3.7 x that of the frames before (measured 2026-12-02). Judged against the
// recent frames it is retried and the retries find the right alignment. That
// was with planes fitted to 5 map neighbours; with the 8 that voxel-sampled
// keyframes get by default (voxel_plane_neighbors_max) it does not slide, nor
// from the end of the coarse pass voxel-sampled frames start from by default
// (voxel_coarse_stride), so the guard is exercised with 5, from the prediction.
TEST(OdometryReal, BalmAlignmentThatFitsWorseThanTheRecentFramesIsRetried) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const BalmRun dense = run_balm(50, 1, 11);
  print("balm frames 50..60, default plane fit", dense);
  EXPECT_EQ(dense.unflagged_beyond(0.1, 1.0), 0);
  EXPECT_EQ(dense.lost, 0);

  slam::OdometryConfig five;
  five.voxel_plane_neighbors_max = 5;
  five.voxel_coarse_stride = 1;
  const BalmRun run = run_balm(50, 1, 11, five);
  print("balm frames 50..60, 5 neighbours", run);
  EXPECT_EQ(run.unflagged_beyond(0.1, 1.0), 0);
  EXPECT_EQ(run.lost, 0);
  EXPECT_LT(run.mean_translation_m(), 0.015);

  // The hazard this guards against: without the relative bound the same frames slide unflagged.
  slam::OdometryConfig absolute_only = five;
  absolute_only.trust.residual_ratio = std::numeric_limits<double>::infinity();
  const BalmRun unguarded = run_balm(50, 1, 11, absolute_only);
  print("balm frames 50..60, absolute bounds only", unguarded);
  EXPECT_GT(unguarded.unflagged_beyond(0.1, 1.0), 0);
}

// A keyframe that fits clearly worse than the ones before (its points moved by
// 12 cm noise) is suspect: its pose is kept, its points stay out of the map, and
// the next keyframe is trusted again.
TEST(OdometryReal, AKeyframeThatFitsWorseIsSuspectAndKeptOutOfTheMap) {
  MLIDAR_REQUIRE_SHARED_DATA();
  std::mt19937 rng(7);
  const auto noisy = [&rng](int index, Scan& scan) {
    if (index != 25) return;
    std::normal_distribution<float> noise(0.0F, 0.12F);
    for (Eigen::Vector3f& p : scan.points)
      for (int axis = 0; axis < 3; ++axis) p[axis] += noise(rng);  // one draw per statement: the same on every compiler
  };
  const BalmRun run = run_balm(20, 1, 8, {}, noisy);
  print("balm frames 20..27, 25 noisy", run);
  const std::vector<bool> expected = {false, false, false, false, false, true, false, false};
  EXPECT_EQ(run.suspect_frames, expected);
  EXPECT_EQ(run.lost, 0);
  EXPECT_EQ(run.map_sizes[5], run.map_sizes[4]) << "the suspect frame's points entered the map";
  EXPECT_GT(run.map_sizes[6], run.map_sizes[5]);
  EXPECT_LT(run.pairs[5].translation_m + run.pairs[6].translation_m, 0.1);  // its pose is still a fair guess
}

// Every second keyframe, 1 s apart (turns up to ~40 deg): the constant-velocity
// prediction is often tens of degrees and metres off and the retries decide.
// Started at 22, keyframe 32 settled 2.1 m off (0.09 deg) unflagged when the
// retries started from the prediction only and stopped at the first to pass;
// started at 24, four frames were lost (measured 2026-12-02). The retries now
// also start from the previous pose, and all run: the tightest is kept.
TEST(OdometryReal, BalmKeyframesOneSecondApartAreRightOrFlagged) {
  MLIDAR_REQUIRE_SHARED_DATA();
  const BalmRun run = run_balm(22, 2, 6);
  print("balm frames 22..32 step 2", run);
  EXPECT_EQ(run.unflagged_beyond(0.1, 2.0), 0);
  EXPECT_EQ(run.lost, 0);
  EXPECT_LT(ate_m(run), 0.05);
}

// Greedy selection (thesis Ch. 5) with epsilon 0.1 on real keyframes 0.5 s
// apart: the set chosen at the constant-velocity start of keyframe 26 settled
// 13 deg off with a tight fit of its own, unflagged (measured 2026-12-02). The
// features it did not use are checked at the final pose; they disagree there,
// and the registration on every feature decides. The hazard was measured with
// voxel samples as the only features (before row recovery); with the still
// keyframes 20-26 on recovered rows the same start no longer slides; nor with
// the 8-neighbour plane fit voxel samples get by default, nor from the end of
// their default coarse pass (voxel_coarse_stride), so this keeps 5 and starts
// at the prediction.
TEST(OdometryReal, BalmGreedySelectionIsCheckedOnTheFeaturesItLeftOut) {
  MLIDAR_REQUIRE_SHARED_DATA();
  slam::OdometryConfig greedy;
  greedy.voxel_plane_neighbors_max = 5;
  greedy.voxel_coarse_stride = 1;
  greedy.registration.selection.method = slam::SelectionMethod::kGreedy;
  greedy.registration.selection.epsilon = 0.1;
  greedy.registration.selection.max_frame_gap_s = 1.0;  // by default keyframes 0.5 s apart register every feature
  const BalmRun run = run_balm(20, 1, 8, greedy);
  print("balm frames 20..27, greedy selection", run);
  EXPECT_EQ(run.unflagged_beyond(0.1, 1.0), 0);
  EXPECT_EQ(run.lost, 0);

  greedy.front_end.recover_rows = false;
  const BalmRun voxel = run_balm(20, 1, 8, greedy);
  print("balm frames 20..27, greedy selection, voxel samples only", voxel);
  EXPECT_EQ(voxel.unflagged_beyond(0.1, 1.0), 0);
  EXPECT_EQ(voxel.lost, 0);

  slam::OdometryConfig unchecked = greedy;
  unchecked.registration.selection.held_out_share = 0.0;
  const BalmRun hazard = run_balm(20, 1, 8, unchecked);
  print("balm frames 20..27, greedy selection unchecked, voxel samples only", hazard);
  EXPECT_GT(hazard.unflagged_beyond(0.1, 1.0), 0);
}

}  // namespace
}  // namespace mlidar::test
