// A given extrinsic judged against the map: an auxiliary LiDAR whose residual
// stays well above the base's is reported once, after `frames` frames; one near
// the base's, a short spike and LiDARs not to be judged are not.
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/calib/extrinsic_check.hpp"

namespace mlidar::calib {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

/// Base residual 3 cm, the auxiliary ones `ratios` times that, each with 20 % seeded noise.
std::vector<double> frame(std::mt19937_64& rng, const std::vector<double>& ratios) {
  std::normal_distribution<double> noise(0.0, 0.2);
  std::vector<double> r{0.03 * (1.0 + 0.2 * noise(rng))};
  for (const double ratio : ratios) r.push_back(0.03 * ratio * (1.0 + noise(rng)));
  return r;
}

TEST(ExtrinsicCheck, AWrongExtrinsicIsReportedOnceAfterTheConfiguredFramesAndARightOneNever) {
  ExtrinsicCheck check(3, {.frames = 20, .residual_ratio = 2.0});
  std::mt19937_64 rng(7);
  const std::vector<bool> checked{false, true, true};
  std::vector<int> reported_at(3, -1);
  for (int k = 0; k < 300; ++k) {
    for (const std::size_t j : check.update(frame(rng, {0.8, 3.0}), checked)) {
      EXPECT_EQ(reported_at[j], -1) << "LiDAR " << j << " reported twice";
      reported_at[j] = k;
    }
  }
  EXPECT_EQ(reported_at[1], -1);
  EXPECT_EQ(reported_at[2], 19);  // the 20th ratio completes the first median
  ASSERT_TRUE(check.median_ratio(1) && check.median_ratio(2));
  EXPECT_NEAR(*check.median_ratio(1), 0.8, 0.15);
  EXPECT_NEAR(*check.median_ratio(2), 3.0, 0.5);
}

TEST(ExtrinsicCheck, ASpikeShorterThanHalfTheFramesIsNotADisagreement) {
  ExtrinsicCheck check(2, {.frames = 20, .residual_ratio = 2.0});
  std::mt19937_64 rng(11);
  for (int k = 0; k < 100; ++k) {
    const double ratio = (k >= 40 && k < 49) ? 6.0 : 1.0;  // 9 high frames of 20
    EXPECT_TRUE(check.update(frame(rng, {ratio}), {false, true}).empty()) << "frame " << k;
  }
}

TEST(ExtrinsicCheck, UncheckedLidarsMissingResidualsAndABaseWithoutOneAddNoRatio) {
  ExtrinsicCheck check(2, {.frames = 5, .residual_ratio = 2.0});
  for (int k = 0; k < 10; ++k) {
    EXPECT_TRUE(check.update(std::vector<double>{0.03, 0.3}, {false, false}).empty());  // being calibrated
    EXPECT_TRUE(check.update(std::vector<double>{0.03, kNan}, {false, true}).empty());  // no scan
    EXPECT_TRUE(check.update(std::vector<double>{-1.0, 0.3}, {false, true}).empty());   // base without a residual
  }
  EXPECT_FALSE(check.median_ratio(1));
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(check.update(std::vector<double>{0.03, 0.3}, {false, true}).empty());
  EXPECT_EQ(check.update(std::vector<double>{0.03, 0.3}, {false, true}), std::vector<std::size_t>{1});
}

TEST(ExtrinsicCheck, AfterAResetTheLidarIsJudgedAfreshAndAZeroRatioTurnsTheCheckOff) {
  ExtrinsicCheck check(2, {.frames = 3, .residual_ratio = 2.0});
  for (int k = 0; k < 3; ++k) check.update(std::vector<double>{0.03, 0.3}, {false, true});
  check.reset(1);
  EXPECT_FALSE(check.median_ratio(1));
  for (int k = 0; k < 2; ++k) EXPECT_TRUE(check.update(std::vector<double>{0.03, 0.3}, {false, true}).empty());
  EXPECT_EQ(check.update(std::vector<double>{0.03, 0.3}, {false, true}), std::vector<std::size_t>{1});

  ExtrinsicCheck off(2, {.frames = 3, .residual_ratio = 0.0});
  for (int k = 0; k < 10; ++k) EXPECT_TRUE(off.update(std::vector<double>{0.03, 0.3}, {false, true}).empty());
  EXPECT_THROW(ExtrinsicCheck(2, {.frames = 0}), std::invalid_argument);
  EXPECT_THROW(ExtrinsicCheck(2, {.residual_ratio = -1.0}), std::invalid_argument);
  EXPECT_THROW(check.update(std::vector<double>{0.03}, {false}), std::invalid_argument);
}

// The one text of a verdict (terminal slam and odometry, report.html): the evidence that judged it, its number to
// one decimal and what it was compared with.
TEST(ExtrinsicCheck, TheEvidenceInWordsNamesWhatJudgedTheExtrinsic) {
  EXPECT_EQ(describe({.frame = 5, .residual_ratio = 3.14159}),
            "at frame 5 its residual was 3.1x the base's, the median of the last extrinsic_check.frames frames; right extrinsics "
            "stay near 1");
  EXPECT_EQ(describe({.frame = 29, .map_ratio = 17.84}),
            "at frame 29 its points in the map lay 17.8x farther from the other LiDARs' surfaces than from its own; right "
            "extrinsics stay near 1");
  EXPECT_EQ(describe({.frame = 5, .frames_lost = true}),
            "the frames after the first could not be registered with the given extrinsics (lost from the start): any of them "
            "may be wrong");
  const std::string vehicle = describe({.frame = 40, .residual_ratio = 2.34, .reference = "the reference LiDAR top"});
  EXPECT_NE(vehicle.find("at frame 40 its residual was 2.3x the reference LiDAR top's,"), std::string::npos) << vehicle;
}

}  // namespace
}  // namespace mlidar::calib
