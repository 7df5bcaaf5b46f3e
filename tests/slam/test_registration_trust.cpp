// Which registration to believe (registration_trust.hpp): the absolute bounds,
// the bound relative to the recent frames, the tightest of several candidates
// and ambiguity between distinct alignments.
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/slam/registration_trust.hpp"

namespace mlidar::test {
namespace {

slam::RegistrationResult candidate(double mean_residual_m, double match_ratio, const SE3& T = SE3::identity()) {
  slam::RegistrationResult r;
  r.T_world_base = T;
  r.queries = 1000;
  r.plane_matches = static_cast<std::size_t>(match_ratio * 1000.0);
  r.mean_residual_m = mean_residual_m;
  return r;
}

SE3 moved(double x_m, double yaw_deg = 0.0) { return SE3(so3_exp(Vec3(0, 0, yaw_deg * std::numbers::pi / 180.0)), Vec3(x_m, 0, 0)); }

TEST(ResidualHistory, IsTheMedianOfTheLastOnes) {
  slam::ResidualHistory history(3);
  EXPECT_TRUE(std::isnan(history.median_m()));
  history.add(0.05);
  EXPECT_DOUBLE_EQ(history.median_m(), 0.05);
  history.add(0.01);
  EXPECT_DOUBLE_EQ(history.median_m(), 0.03);
  history.add(0.9);
  history.add(0.04);  // 0.05 leaves: {0.01, 0.9, 0.04}
  EXPECT_DOUBLE_EQ(history.median_m(), 0.04);
  history.add(std::nan(""));
  EXPECT_DOUBLE_EQ(history.median_m(), 0.04);
}

TEST(TrustRule, RelativeBoundHasAFloorAndNeedsAHistory) {
  const slam::TrustConfig config;  // ratio 2, floor 0.03 m, absolute 0.2 m / 0.5
  const slam::TrustRule none{config, std::nan("")};  // no history: an absolute bound of 0.06 m
  EXPECT_TRUE(none.trusted(candidate(0.059, 0.9)));
  EXPECT_FALSE(none.trusted(candidate(0.19, 0.9)));
  EXPECT_TRUE(none.acceptable(candidate(0.19, 0.9)));
  EXPECT_FALSE(none.acceptable(candidate(0.21, 0.9)));
  EXPECT_FALSE(none.acceptable(candidate(0.05, 0.4)));
  const slam::TrustRule recent{config, 0.05};
  EXPECT_TRUE(recent.trusted(candidate(0.099, 0.9)));
  EXPECT_FALSE(recent.trusted(candidate(0.101, 0.9)));
  EXPECT_TRUE(recent.acceptable(candidate(0.101, 0.9)));
  const slam::TrustRule tight{config, 0.005};  // 2 x 5 mm is below the floor
  EXPECT_TRUE(tight.trusted(candidate(0.029, 0.9)));
  EXPECT_FALSE(tight.trusted(candidate(0.031, 0.9)));
}

TEST(TrustRule, TheSecondFrameMayMatchFewerFeaturesOnlyWithATightWellConditionedFit) {
  const slam::TrustConfig config;  // 0.5 of the features; 0.3 for the second frame within 0.06 m
  const slam::TrustRule first{config, std::nan(""), true}, later{config, std::nan(""), false};
  slam::RegistrationResult right = candidate(0.027, 0.46);  // the single RS-LiDAR-16's second frame at 7.5 m/s
  right.converged = true;
  EXPECT_TRUE(first.trusted(right));
  EXPECT_FALSE(later.acceptable(right));
  slam::RegistrationResult turned = right;  // a wrong alignment after a 120 deg turn
  turned.mean_residual_m = 0.13;
  EXPECT_FALSE(first.acceptable(turned));
  slam::RegistrationResult sliding = right;
  sliding.degenerate = true;
  EXPECT_FALSE(first.acceptable(sliding));
  slam::RegistrationResult unfinished = right;
  unfinished.converged = false;
  EXPECT_FALSE(first.acceptable(unfinished));
  EXPECT_FALSE(first.acceptable(candidate(0.027, 0.29)));  // converged or not, too few
}

TEST(ChooseRegistration, KeepsTheTightestAcceptableAndJudgesIt) {
  const slam::TrustRule rule{slam::TrustConfig{}, 0.05};
  // The tightest of all is not acceptable (too few matches): the next one wins.
  const std::vector<slam::RegistrationResult> candidates = {candidate(0.15, 0.9, moved(1.0)), candidate(0.01, 0.3, moved(2.0)),
                                                            candidate(0.06, 0.9, moved(3.0)), candidate(0.061, 0.9, moved(3.05))};
  const slam::Choice choice = slam::choose_registration(candidates, rule);
  EXPECT_EQ(choice.best, 2u);
  EXPECT_EQ(choice.trust, slam::Trust::kTrusted);  // 3.05 m is the same alignment (5 cm apart)
  EXPECT_FALSE(choice.rival.has_value());

  const std::vector<slam::RegistrationResult> worse = {candidate(0.15, 0.9), candidate(0.12, 0.9)};
  EXPECT_EQ(slam::choose_registration(worse, rule).trust, slam::Trust::kResidual);
  EXPECT_EQ(slam::choose_registration(worse, rule).best, 1u);

  const std::vector<slam::RegistrationResult> none = {candidate(0.3, 0.9), candidate(0.05, 0.2)};
  EXPECT_EQ(slam::choose_registration(none, rule).trust, slam::Trust::kLost);
  EXPECT_EQ(slam::choose_registration(none, rule).best, 0u);
}

TEST(ChooseRegistration, AnAlignmentElsewhereThatFitsAsWellMakesItAmbiguous) {
  const slam::TrustRule rule{slam::TrustConfig{}, 0.05};
  // 2.1 m apart, 0.051 vs 0.055 m (within 1.15 x): ambiguous.
  const std::vector<slam::RegistrationResult> slid = {candidate(0.055, 0.9, moved(2.1)), candidate(0.051, 0.9)};
  const slam::Choice choice = slam::choose_registration(slid, rule);
  EXPECT_EQ(choice.best, 1u);
  EXPECT_EQ(choice.trust, slam::Trust::kAmbiguous);
  EXPECT_EQ(choice.rival, 0u);
  // Turned by 5 deg in place: also elsewhere.
  const std::vector<slam::RegistrationResult> turned = {candidate(0.051, 0.9), candidate(0.052, 0.9, moved(0.0, 5.0))};
  EXPECT_EQ(slam::choose_registration(turned, rule).trust, slam::Trust::kAmbiguous);
  // Clearly worse elsewhere (0.076 vs 0.051 m: BALM 110 -> 112): the best is unique.
  const std::vector<slam::RegistrationResult> clear = {candidate(0.076, 0.9, moved(2.1)), candidate(0.051, 0.9)};
  EXPECT_EQ(slam::choose_registration(clear, rule).trust, slam::Trust::kTrusted);
}

// The retries refine a coarse end pose unless it converged to a fit no
// registration may keep; the tightest always, converged or not.
TEST(RefinablePoses, DropsConvergedFitsAboveTheAcceptableBoundButNeverTheTightest) {
  const auto coarse = [](double mean_residual_m, bool converged, double x_m) {
    slam::RegistrationResult r = candidate(mean_residual_m, 0.9, moved(x_m));
    r.converged = converged;
    return r;
  };
  const std::vector<slam::RegistrationResult> results = {
      coarse(0.30, true, 1.0),   // a local minimum that fits badly: dropped
      coarse(0.06, true, 2.0),   // kept
      coarse(0.35, false, 3.0),  // still moving: kept
      coarse(0.20, true, 4.0),   // on the bound: kept
  };
  const std::vector<SE3> kept = slam::refinable_poses(results, 0.2);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_DOUBLE_EQ(kept[0].translation().x(), 2.0);
  EXPECT_DOUBLE_EQ(kept[1].translation().x(), 3.0);
  EXPECT_DOUBLE_EQ(kept[2].translation().x(), 4.0);
  // All converged badly: the tightest still runs, so the frame is judged, not dropped unseen.
  const std::vector<slam::RegistrationResult> bad = {coarse(0.4, true, 1.0), coarse(0.3, true, 2.0), coarse(0.5, true, 3.0)};
  const std::vector<SE3> tightest = slam::refinable_poses(bad, 0.2);
  ASSERT_EQ(tightest.size(), 1u);
  EXPECT_DOUBLE_EQ(tightest[0].translation().x(), 2.0);
  EXPECT_THROW(slam::refinable_poses({}, 0.2), std::invalid_argument);
}

TEST(DistinctPoses, KeepsTheFirstOfEachAlignmentReachedTwice) {
  const std::vector<SE3> poses = {moved(0.0), moved(0.04), moved(0.0, 0.4), moved(0.06), moved(0.0, 0.6), moved(0.0), moved(0.03, 0.3)};
  const std::vector<SE3> kept = slam::distinct_poses(poses, 0.05, 0.5);
  // 0.04 m and 0.4 deg from the first are the same; 0.06 m and 0.6 deg are not (either bound decides).
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_DOUBLE_EQ(kept[0].translation().x(), 0.0);
  EXPECT_DOUBLE_EQ(kept[1].translation().x(), 0.06);
  EXPECT_NEAR(so3_log(kept[2].rotation()).z() * 180.0 / std::numbers::pi, 0.6, 1e-9);
  EXPECT_TRUE(slam::distinct_poses({}, 0.05, 0.5).empty());
}

// A degenerate registration may hold the weak direction at its start but not
// move far from the prediction on geometry that does not pin the move.
TEST(JudgeDegenerateCorrection, ADegenerateRegistrationThatMovedFarIsSuspect) {
  const slam::TrustConfig config;  // 0.3 m, 3 deg
  const SE3 prediction = moved(1.0, 10.0);
  slam::RegistrationResult r = candidate(0.03, 0.9, prediction * moved(0.5));
  r.degenerate = true;
  EXPECT_EQ(slam::judge_degenerate_correction(slam::Trust::kTrusted, r, prediction, config), slam::Trust::kDegenerate);
  r.T_world_base = prediction * moved(0.0, 5.0);
  EXPECT_EQ(slam::judge_degenerate_correction(slam::Trust::kTrusted, r, prediction, config), slam::Trust::kDegenerate);
  r.T_world_base = prediction * moved(0.2, 2.0);  // within both bounds
  EXPECT_EQ(slam::judge_degenerate_correction(slam::Trust::kTrusted, r, prediction, config), slam::Trust::kTrusted);
  r.T_world_base = prediction * moved(0.5);
  r.degenerate = false;  // well constrained: the correction is the geometry's
  EXPECT_EQ(slam::judge_degenerate_correction(slam::Trust::kTrusted, r, prediction, config), slam::Trust::kTrusted);
  r.degenerate = true;  // already judged: kept
  EXPECT_EQ(slam::judge_degenerate_correction(slam::Trust::kAmbiguous, r, prediction, config), slam::Trust::kAmbiguous);
  EXPECT_STREQ(slam::trust_name(slam::Trust::kDegenerate), "degenerate");
}

}  // namespace
}  // namespace mlidar::test
