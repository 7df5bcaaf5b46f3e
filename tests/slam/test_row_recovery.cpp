// Row recovery for clouds without a ring channel: against ray-cast scans whose
// beams are known (plain, tilted during the sweep, beams above the origin), a
// cloud with no beams at all, and real Ouster keyframes.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/point_table.hpp"
#include "mlidar/slam/frontend.hpp"
#include "mlidar/slam/row_recovery.hpp"
#include "synthetic_scans.hpp"
#include "test_support.hpp"

namespace mlidar::slam {
namespace {

const test::AxisBox kRoom{{-12, -9, -2}, {14, 10, 4}, -1};

test::CastScan room_scan(const LidarModel& model) {
  return test::cast_scan(model, -1.6, {{{4, -1, -1.6}, {5, 1, 0.5}, 1}, {{-3, 5, -1.6}, {-1, 6, 1.5}, 2}}, &kRoom);
}

/// Share of points whose recovered row is their beam's (beams counted by ascending elevation).
double agreement(const test::CastScan& cast, const LidarModel& model, const RecoveredRows& rows) {
  std::vector<std::size_t> order(model.rings());
  for (std::size_t r = 0; r < order.size(); ++r) order[r] = r;
  std::sort(order.begin(), order.end(),
            [&model](std::size_t a, std::size_t b) { return model.vertical_angles_deg[a] < model.vertical_angles_deg[b]; });
  std::vector<std::uint16_t> rank(model.rings());
  for (std::size_t k = 0; k < order.size(); ++k) rank[order[k]] = static_cast<std::uint16_t>(k);
  std::size_t same = 0;
  for (std::size_t i = 0; i < cast.scan.size(); ++i) same += rows.ring[i] == rank[cast.scan.ring[i]] ? 1 : 0;
  return static_cast<double>(same) / static_cast<double>(cast.scan.size());
}

TEST(RowRecovery, FindsEveryBeamOfARingLessScan) {
  for (const int rings : {16, 32, 64}) {
    const LidarModel model = test::uniform_model(rings, -22.0, 22.0, 0.35);
    const test::CastScan cast = room_scan(model);
    const auto rows = recover_rows(cast.scan.points);
    ASSERT_TRUE(rows.has_value()) << rings << " beams";
    EXPECT_EQ(rows->model.rings(), model.rings());
    EXPECT_GT(agreement(cast, model, *rows), 0.999) << rings << " beams";
    for (std::size_t r = 0; r < model.rings(); ++r) EXPECT_NEAR(rows->model.vertical_angles_deg[r], model.vertical_angles_deg[r], 0.06);
    EXPECT_NEAR(rows->model.horizontal_resolution_deg, 0.35, 0.02);
    EXPECT_NEAR(rows->origin_z_m, 0.0, 1e-12);
  }
}

// A ring channel in the sensor's firing order (interleaved, as Velodyne's) and
// no model: rows by ascending elevation, angles measured from the points.
TEST(RowRecovery, TakesRowsFromARingChannelInAnyOrder) {
  const LidarModel model = test::uniform_model(16, -15.0, 15.0, 0.2);
  test::CastScan cast = room_scan(model);
  const auto interleaved = [](std::uint16_t beam) { return static_cast<std::uint16_t>(beam % 2 == 0 ? beam / 2 : 8 + beam / 2); };
  std::vector<std::uint16_t> channel;
  for (const std::uint16_t beam : cast.scan.ring) channel.push_back(interleaved(beam));
  const auto rows = rows_from_ring_channel(cast.scan.points, channel);
  ASSERT_TRUE(rows.has_value());
  ASSERT_EQ(rows->model.rings(), 16U);
  for (std::size_t r = 0; r < 16; ++r) EXPECT_NEAR(rows->model.vertical_angles_deg[r], model.vertical_angles_deg[r], 1e-4);
  EXPECT_EQ(rows->ring, cast.scan.ring);  // beams of the uniform model ascend already
  EXPECT_NEAR(rows->model.horizontal_resolution_deg, 0.2, 0.01);
  EXPECT_FALSE(rows_from_ring_channel(cast.scan.points, std::vector<std::uint16_t>(cast.scan.size(), 0)).has_value()) << "one ring";
}

// Deskewed to one instant, a sweep during which the sensor tilted by 2 deg
// has each beam's elevation drift with azimuth (and jump at the seam).
TEST(RowRecovery, FollowsBeamsThatDriftWithAzimuth) {
  const LidarModel model = test::uniform_model(64, -22.0, 22.0, 0.35);
  test::CastScan cast = room_scan(model);
  for (Eigen::Vector3f& p : cast.scan.points) {
    double azimuth = std::atan2(p.y(), p.x());
    if (azimuth < 0.0) azimuth += 2.0 * std::numbers::pi;
    const double tilt = 2.0 * std::numbers::pi / 180.0 * azimuth / (2.0 * std::numbers::pi);
    p = Eigen::AngleAxisf(static_cast<float>(tilt), Eigen::Vector3f::UnitY()) * p;
  }
  const auto rows = recover_rows(cast.scan.points);
  ASSERT_TRUE(rows.has_value());
  EXPECT_EQ(rows->model.rings(), 64U);
  EXPECT_GT(agreement(cast, model, *rows), 0.99);
}

// Beams leaving 3.6 cm above the frame's origin (Ouster): near points read high.
TEST(RowRecovery, FindsTheBeamsHeightAboveTheOrigin) {
  const LidarModel model = test::uniform_model(64, -22.0, 22.0, 0.35);
  test::CastScan cast = room_scan(model);
  for (Eigen::Vector3f& p : cast.scan.points) p.z() += 0.036F;
  const auto rows = recover_rows(cast.scan.points);
  ASSERT_TRUE(rows.has_value());
  EXPECT_NEAR(rows->origin_z_m, 0.04, 0.011);
  EXPECT_EQ(rows->model.rings(), 64U);
  EXPECT_GT(agreement(cast, model, *rows), 0.99);
}

/// Points over a 70 deg cone at 2-30 m, as a solid-state scanner's rosette: no beams.
Scan rosette_scan(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> range(2.0, 30.0);
  Scan scan;
  while (scan.points.size() < count) {
    const double y = unit(rng), z = unit(rng);
    if (y * y + z * z > 1.0) continue;
    scan.points.push_back((range(rng) * Eigen::Vector3d(1.0, 0.7 * y, 0.7 * z).normalized()).cast<float>());
  }
  return scan;
}

// A cloud with no beams (points spread over a 70 deg cone, as a solid-state
// scanner's rosette over a keyframe) has no rows.
TEST(RowRecovery, FindsNoRowsWhereThereAreNoBeams) {
  for (const std::size_t count : {3400U, 20000U, 100000U}) {
    const auto rows = recover_rows(rosette_scan(count, 3).points);
    EXPECT_FALSE(rows.has_value()) << count << " points: " << (rows ? rows->model.rings() : 0) << " rows";
  }
}

/// The row source the front end gives each scan in turn, one LiDAR without a model, one workspace.
std::vector<RowSource> row_sources(const std::vector<const Scan*>& scans, int max_skip) {
  FrontEndConfig config;
  config.recover_rows_max_skip = max_skip;
  const LidarSetup lidar{"solid", LidarModel{}, SE3::identity()};
  FrontEndWorkspace workspace;
  std::vector<RowSource> sources;
  for (const Scan* scan : scans) {
    LidarFeatures features;
    StageSeconds seconds{};
    run_front_end(*scan, scan->stamp, lidar, BodyVelocity{}, config, workspace, features, seconds);
    sources.push_back(features.row_source);
  }
  return sources;
}

// After a scan without rows the next 1, then 2, 4, ... scans (up to the cap)
// take the voxel samples unsearched, even one that would show rows; a scan
// searched and recovered resets the back-off.
TEST(RowRecovery, TheFrontEndBacksOffFromScansThatShowNoRows) {
  const LidarModel model = test::uniform_model(16, -15.0, 15.0, 0.4);
  Scan beams = room_scan(model).scan;
  beams.ring.clear();
  const Scan none = rosette_scan(20000, 5);
  constexpr RowSource kFallback = RowSource::kVoxelFallback, kRows = RowSource::kRecovered;
  // none: searched, refused, skip 1; beams: skipped; none: refused, skip 2; beams x2 skipped; beams found (reset);
  // none: refused, skip 1 again.
  const std::vector<const Scan*> sequence = {&none, &beams, &none, &beams, &beams, &beams, &beams, &none, &beams, &beams};
  EXPECT_EQ(row_sources(sequence, 16),
            (std::vector<RowSource>{kFallback, kFallback, kFallback, kFallback, kFallback, kRows, kRows, kFallback, kFallback, kRows}));
  // The cap: at most one scan skipped after each refusal.
  EXPECT_EQ(row_sources({&none, &beams, &none, &beams, &none, &beams, &beams}, 1),
            (std::vector<RowSource>{kFallback, kFallback, kFallback, kFallback, kFallback, kFallback, kRows}));
  // 0: every scan searched.
  EXPECT_EQ(row_sources({&none, &beams, &none, &beams}, 0), (std::vector<RowSource>{kFallback, kRows, kFallback, kRows}));
}

// BALM's Ouster keyframes (already deskewed): 64 beams over a 90 deg field of
// view. Still ones show exactly the 64, beams 3-5 cm above the origin; those
// taken while moving merge sweeps from several poses (frame 22: 128 peaks,
// two sweeps; others 70-140 interleaving their beams) and must not pass for
// a single sweep.
Scan balm_keyframe(int index) {
  const auto path = mlidar::test::shared_data() / "real" / "balm_ouster" / "frames" / ("full" + std::to_string(index) + ".pcd");
  return io::to_scan(io::read_cloud(path).table, path.string());
}

TEST(RowRecovery, RecoversTheBeamsOfStillRealOusterKeyframes) {
  MLIDAR_REQUIRE_SHARED_DATA();
  for (const int index : {20, 21, 23, 24, 25}) {
    const auto rows = recover_rows(balm_keyframe(index).points);
    ASSERT_TRUE(rows.has_value()) << "frame " << index;
    std::cout << "frame " << index << ": " << rows->model.rings() << " rows, " << rows->assigned_share * 100 << " % of points, width "
              << rows->width_ratio << ", z0 " << rows->origin_z_m << " m, " << rows->model.horizontal_resolution_deg << " deg per column\n";
    EXPECT_EQ(rows->model.rings(), 64U) << "frame " << index;
    EXPECT_GT(rows->assigned_share, 0.995);
    EXPECT_NEAR(rows->model.vertical_angles_deg.front(), -45.2, 0.7);  // from z0 above the origin
    EXPECT_NEAR(rows->model.vertical_angles_deg.back(), 45.2, 0.7);
    EXPECT_GE(rows->origin_z_m, 0.02);
    EXPECT_LE(rows->origin_z_m, 0.06);
  }
}

TEST(RowRecovery, KeyframesMergedWhileMovingAreNotTakenForASweep) {
  MLIDAR_REQUIRE_SHARED_DATA();
  RowRecoveryConfig accept_all;
  accept_all.max_width_ratio = 1.0;
  for (const int index : {22, 57, 100, 112, 119}) {
    const Scan scan = balm_keyframe(index);
    EXPECT_FALSE(recover_rows(scan.points).has_value()) << "frame " << index;
    const auto peaks = recover_rows(scan.points, accept_all);
    ASSERT_TRUE(peaks.has_value());
    std::cout << "frame " << index << ": " << peaks->model.rings() << " peaks, width " << peaks->width_ratio << '\n';
    EXPECT_GT(peaks->model.rings(), 64U);
    EXPECT_GT(peaks->width_ratio, 0.07);
  }
}

}  // namespace
}  // namespace mlidar::slam
