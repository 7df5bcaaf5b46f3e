// Front end against ray-cast scenes whose true surfaces are known.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "mlidar/slam/deskew.hpp"
#include "mlidar/slam/features.hpp"
#include "mlidar/slam/range_image.hpp"
#include "mlidar/slam/segmentation.hpp"
#include "synthetic_scans.hpp"

namespace mlidar::slam {
namespace {

using test::AxisBox;

TEST(RangeImage, NearestRowHandlesUnevenTables) {
  const std::vector<double> table = {-25.0, -15.0, -11.0, -8.0, -6.0, -5.0, -4.5, 0.0, 2.0, 15.0};
  for (std::size_t row = 0; row < table.size(); ++row) {
    EXPECT_EQ(nearest_row(table, table[row]), static_cast<int>(row));
    EXPECT_EQ(nearest_row(table, table[row] + 0.2), static_cast<int>(row));  // every gap is > 0.4 deg
  }
  EXPECT_EQ(nearest_row(table, -90.0), 0);
  EXPECT_EQ(nearest_row(table, 90.0), 9);
}

TEST(RangeImage, RowsFromElevationMatchRings) {
  const LidarModel model = test::uniform_model(16, -15.0, 15.0, 1.0);
  const auto cast = test::cast_scan(model, -1.5, {{{4, -30, -3}, {5, 30, 5}, 1}, {{-5, -30, -3}, {-4, 30, 5}, 2}});
  RangeImage with_ring, from_elevation;
  build_range_image(cast.scan.points, cast.scan.ring, model, with_ring);
  build_range_image(cast.scan.points, {}, model, from_elevation);
  EXPECT_EQ(with_ring.index, from_elevation.index);
  const std::size_t filled =
      static_cast<std::size_t>(std::count_if(with_ring.index.begin(), with_ring.index.end(), [](int i) { return i >= 0; }));
  EXPECT_EQ(filled, cast.scan.size());  // one point per pixel: none lost, none merged
  for (std::size_t p = 0; p < with_ring.index.size(); ++p)
    if (with_ring.index[p] >= 0) {
      EXPECT_FLOAT_EQ(with_ring.range[p], cast.scan.points[static_cast<std::size_t>(with_ring.index[p])].norm());
    }
}

TEST(RangeImage, ColumnIsTheNearestAzimuthBinClockwiseFromX) {
  const LidarModel model = test::uniform_model(16, -15.0, 15.0, 0.2);  // 1800 columns
  // Column c holds azimuths -(c +- 0.5) bins (clockwise), so a bin and a fraction f away lands in c + round(f).
  for (const int bin : {0, 1, 450, 899, 900, 901, 1350, 1799})
    for (const double fraction : {-0.49, -0.3, 0.0, 0.3, 0.49, 0.51, -0.51}) {
      const double azimuth_rad = -(bin + fraction) * 0.2 * std::numbers::pi / 180.0;
      const std::vector<Eigen::Vector3f> point = {
          Eigen::Vector3f(static_cast<float>(10.0 * std::cos(azimuth_rad)), static_cast<float>(10.0 * std::sin(azimuth_rad)), 0.0F)};
      RangeImage image;
      build_range_image(point, std::vector<std::uint16_t>{7}, model, image);
      const int expected = ((bin + (fraction > 0.5 ? 1 : fraction < -0.5 ? -1 : 0)) % 1800 + 1800) % 1800;
      const auto filled = std::find(image.index.begin(), image.index.end(), 0) - image.index.begin();
      EXPECT_EQ(filled, image.pixel(7, expected)) << "bin " << bin << " fraction " << fraction;
    }
}

TEST(Features, SelectSmallestPutsTheSmallestFirstAsASortWould) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t size = rng() % 400;
    // Distinct keys as extract_features makes them, and (every third trial) many equal ones.
    const std::uint64_t range = trial % 3 == 2 ? 4 : ~0ULL;
    std::vector<std::uint64_t> keys(size);
    for (auto& key : keys) key = rng() % range;
    const std::size_t count = size == 0 ? 0 : rng() % (size + 1);
    std::vector<std::uint64_t> sorted = keys;
    std::sort(sorted.begin(), sorted.end());
    select_smallest(keys, count);
    std::vector<std::uint64_t> first(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(count));
    std::vector<std::uint64_t> rest(keys.begin() + static_cast<std::ptrdiff_t>(count), keys.end());
    std::sort(first.begin(), first.end());
    std::sort(rest.begin(), rest.end());
    ASSERT_TRUE(std::equal(first.begin(), first.end(), sorted.begin())) << "trial " << trial << " size " << size << " count " << count;
    ASSERT_TRUE(std::equal(rest.begin(), rest.end(), sorted.begin() + static_cast<std::ptrdiff_t>(count))) << "trial " << trial;
  }
}

struct SegmentedScene {
  test::CastScan cast;
  RangeImage image;
  Segmentation seg;
};

SegmentedScene segment_boxes(double threshold_deg) {
  const LidarModel model = test::uniform_model(32, -25.0, 10.0, 0.4);
  const std::vector<AxisBox> boxes = {{{5, -1, -1.5}, {6, 1, 1.0}, 1},             // box ahead
                                      {{-2, 6, -1.5}, {2, 7, 0.5}, 2},             // box to the left
                                      {{-8, -6, -1.5}, {-6, -4, 2.0}, 3},          // box behind right, seen obliquely
                                      {{2.0, -9.3, -1.5}, {2.3, -9.0, -1.2}, 4}};  // a rock: few points
  SegmentedScene out;
  out.cast = test::cast_scan(model, -1.5, boxes);
  build_range_image(out.cast.scan.points, out.cast.scan.ring, model, out.image);
  SegmentationConfig config;
  config.angle_threshold_deg = threshold_deg;
  segment_range_image(out.image, out.cast.scan.points, model.vertical_angles_deg, Eigen::Vector3f::UnitZ(), config, out.seg);
  return out;
}

/// Labels per object id (points above the ground-contact rows), and the ground recall within 15 m.
std::map<int, std::set<int>> labels_by_object(const SegmentedScene& s, double& ground_recall) {
  std::map<int, std::set<int>> labels;
  std::size_t ground_total = 0, ground_labelled = 0;
  for (std::size_t p = 0; p < s.image.index.size(); ++p) {
    if (s.image.index[p] < 0) continue;
    const auto i = static_cast<std::size_t>(s.image.index[p]);
    const int id = s.cast.hit_id[i];
    if (id == 0 && s.cast.scan.points[i].head<2>().norm() < 15.0) {
      ++ground_total;
      ground_labelled += s.seg.label[p] == Segmentation::kGround ? 1 : 0;
    }
    if (id == 4 || (id > 0 && s.cast.scan.points[i].z() > -1.2)) labels[id].insert(s.seg.label[p]);
  }
  ground_recall = static_cast<double>(ground_labelled) / static_cast<double>(ground_total);
  return labels;
}

TEST(Segmentation, BogoslavskyiThresholdGivesOneClusterPerObject) {
  double ground_recall = 0.0;
  auto labels = labels_by_object(segment_boxes(10.0), ground_recall);
  EXPECT_GT(ground_recall, 0.95);
  for (int id = 1; id <= 3; ++id) {
    ASSERT_EQ(labels[id].size(), 1u) << "object " << id;
    EXPECT_GE(*labels[id].begin(), 1) << "object " << id;
  }
  EXPECT_NE(*labels[1].begin(), *labels[2].begin());
  EXPECT_NE(*labels[2].begin(), *labels[3].begin());
  EXPECT_NE(*labels[1].begin(), *labels[3].begin());
  ASSERT_FALSE(labels[4].empty()) << "the rock was not hit";
  for (const int label : labels[4]) EXPECT_LE(label, Segmentation::kGround) << "small cluster kept as an object";
}

TEST(Segmentation, ThesisThresholdKeepsClustersPure) {
  // 60 deg (thesis) splits surfaces seen at > 30 deg incidence into strips,
  // but no cluster may join two objects and every object stays mostly kept.
  const SegmentedScene s = segment_boxes(60.0);
  double ground_recall = 0.0;
  auto labels = labels_by_object(s, ground_recall);
  EXPECT_GT(ground_recall, 0.95);
  std::map<int, int> object_of_label;
  for (int id = 1; id <= 3; ++id) {
    for (const int label : labels[id]) {
      if (label <= 0) continue;
      const auto [it, inserted] = object_of_label.emplace(label, id);
      EXPECT_TRUE(inserted || it->second == id) << "label " << label << " joins objects " << it->second << " and " << id;
    }
    EXPECT_GT(labels[id].size(), 0u);
  }
  for (const int label : labels[4]) EXPECT_LE(label, Segmentation::kGround) << "small cluster kept as an object";
}

/// Distance from p to the nearest of the room's 12 edges (segments between faces).
double distance_to_room_edge(const Eigen::Vector3d& p, const AxisBox& room) {
  double best = 1e9;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (const double u : {room.min[a], room.max[a]})
      for (const double v : {room.min[b], room.max[b]}) best = std::min(best, std::hypot(p[a] - u, p[b] - v));
  }
  return best;
}

double distance_to_room_face(const Eigen::Vector3d& p, const AxisBox& room) {
  return std::min((p - room.min).cwiseAbs().minCoeff(), (p - room.max).cwiseAbs().minCoeff());
}

TEST(Features, EdgesOnRoomCornersPlanesOnFaces) {
  const LidarModel model = test::uniform_model(32, -30.0, 30.0, 0.4);
  const AxisBox room{{-5.0, -4.0, -1.5}, {6.0, 3.5, 2.0}, -1};
  auto cast = test::cast_scan(model, -100.0, {}, &room);
  RangeImage image;
  build_range_image(cast.scan.points, cast.scan.ring, model, image);
  Segmentation seg;
  segment_range_image(image, cast.scan.points, model.vertical_angles_deg, Eigen::Vector3f::UnitZ(), {}, seg);
  FeatureWorkspace ws;
  FeatureIndices features;
  extract_features(image, seg, {}, ws, features);
  ASSERT_GT(features.edges.size(), 20u);
  ASSERT_GT(features.planes.size(), 500u);
  for (const auto i : features.edges) EXPECT_LT(distance_to_room_edge(cast.scan.points[i].cast<double>(), room), 0.35);
  std::size_t near_edge = 0;
  for (const auto i : features.planes) {
    const Eigen::Vector3d p = cast.scan.points[i].cast<double>();
    EXPECT_LT(distance_to_room_face(p, room), 1e-4);
    near_edge += distance_to_room_edge(p, room) < 0.1 ? 1 : 0;
  }
  EXPECT_LT(near_edge, features.planes.size() / 20);  // planes stay off the room's edges
}

TEST(Features, CurvatureOfAFlatRowIsZero) {
  std::vector<float> ranges(20, 7.5F), curvature(20);
  row_curvature(ranges, curvature);
  for (int i = 5; i < 15; ++i) EXPECT_FLOAT_EQ(curvature[static_cast<std::size_t>(i)], 0.0F);
  EXPECT_TRUE(std::isinf(curvature[0]));
  EXPECT_TRUE(std::isinf(curvature[19]));
}

// The LOAM selection rule written out with one full sort per sector: the
// oracle for extract_features' lazy partial ordering (thresholds 0: every
// pixel is a candidate, so the picks run deep into each sector's order).
FeatureIndices select_by_full_sort(std::span<const float> curvature, std::span<const std::uint8_t> ground, const FeatureConfig& config) {
  FeatureIndices out;
  const int n = static_cast<int>(curvature.size());
  std::vector<std::uint8_t> blocked(curvature.size(), 0);
  const auto block = [&](int i) {
    for (int k = std::max(0, i - 5); k <= std::min(n - 1, i + 5); ++k) blocked[static_cast<std::size_t>(k)] = 1;
  };
  for (int s = 0; s < config.sectors; ++s) {
    std::vector<int> order;
    for (int i = 5 + (n - 10) * s / config.sectors; i < 5 + (n - 10) * (s + 1) / config.sectors; ++i) order.push_back(i);
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return curvature[static_cast<std::size_t>(a)] > curvature[static_cast<std::size_t>(b)]; });
    int edges = 0, planes = 0;
    for (const int i : order)
      if (edges < config.edges_per_sector && blocked[static_cast<std::size_t>(i)] == 0 && ground[static_cast<std::size_t>(i)] == 0) {
        out.edges.push_back(static_cast<std::uint32_t>(i));
        block(i);
        ++edges;
      }
    for (auto it = order.rbegin(); it != order.rend(); ++it)
      if (planes < config.planes_per_sector && blocked[static_cast<std::size_t>(*it)] == 0) {
        out.planes.push_back(static_cast<std::uint32_t>(*it));
        block(*it);
        ++planes;
      }
  }
  return out;
}

TEST(Features, LazyOrderingPicksWhatAFullSortPicks) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> range(4.0F, 6.0F);
  RangeImage image;
  image.rows = 1;
  image.cols = 400;
  Segmentation seg;
  std::vector<std::uint8_t> ground;
  for (int col = 0; col < image.cols; ++col) {
    image.range.push_back(range(rng));
    image.index.push_back(col);
    ground.push_back(col % 7 == 0 ? 1 : 0);
    seg.label.push_back(ground.back() != 0 ? Segmentation::kGround : 1);
  }
  std::vector<float> curvature(image.range.size());
  row_curvature(image.range, curvature);
  FeatureConfig config;
  config.sectors = 3;
  config.edges_per_sector = 5;
  config.planes_per_sector = 9;  // 3 x (5 + 9) picks blocking 11 pixels each: about all of the row
  config.edge_threshold = 0.0;
  config.plane_threshold = 1e9;
  config.occlusion_jump_m = 1e9;
  config.grazing_ratio = 1e9;
  FeatureWorkspace ws;
  FeatureIndices features;
  extract_features(image, seg, config, ws, features);
  const FeatureIndices expected = select_by_full_sort(curvature, ground, config);
  EXPECT_EQ(features.edges, expected.edges);
  EXPECT_EQ(features.planes, expected.planes);
  EXPECT_GT(features.planes.size(), 15u);
}

TEST(RangeImage, FastAtan2MatchesStdAtan2) {
  double worst = 0.0;
  for (int i = -1800; i <= 1800; ++i) {
    const double angle = i * 0.1 * std::numbers::pi / 180.0 + 1e-4 * (i % 7);
    for (const double radius : {1e-3, 1.0, 150.0}) {
      const double y = radius * std::sin(angle);
      const double x = radius * std::cos(angle);
      worst = std::max(worst, std::abs(fast_atan2(y, x) - std::atan2(y, x)));
    }
  }
  EXPECT_LT(worst, 5e-8);
  for (const double y : {0.0, -0.0, 1.0, -1.0})
    for (const double x : {0.0, -0.0, 1.0, -1.0})
      EXPECT_NEAR(fast_atan2(y, x), x == 0.0 && y == 0.0 ? 0.0 : std::atan2(y, x), 5e-8) << y << " " << x;
}

TEST(Deskew, TrueMotionRestoresTheCloud) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coord(-20.0, 20.0), when(-0.02, 0.11);
  BodyVelocity velocity;
  velocity.linear = Vec3(8.0, -1.0, 0.3);
  velocity.angular = Vec3(0.1, -0.2, 0.9);
  const SE3 T_base_lidar(so3_exp(Vec3(0.3, 0.1, -0.5)), Vec3(0.8, 0.0, -1.3));
  std::vector<Eigen::Vector3f> world, raw;
  std::vector<float> times;
  for (int i = 0; i < 500; ++i) {
    const Vec3 p_stamp(coord(rng), coord(rng), coord(rng) / 4.0);  // base frame at the stamp
    const float t = static_cast<float>(when(rng));
    // The LiDAR sees p at time t from pose_at(t): p_lidar = T_base_lidar^-1 pose_at(t)^-1 p.
    raw.push_back((T_base_lidar.inverse() * velocity.pose_at(t).inverse() * p_stamp).cast<float>());
    world.push_back(p_stamp.cast<float>());
    times.push_back(t);
  }
  std::vector<Eigen::Vector3f> out(raw.size());
  deskew_to_base(raw, times, {}, T_base_lidar, velocity, out);
  double worst = 0.0, distorted = 0.0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    worst = std::max(worst, static_cast<double>((out[i] - world[i]).norm()));
    distorted = std::max(distorted, static_cast<double>(((T_base_lidar * raw[i]) - world[i]).norm()));
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(distorted, 0.5);  // the test has motion to undo
  const std::vector<std::uint32_t> pick = {3, 499, 0};
  std::vector<Eigen::Vector3f> some(3);
  deskew_to_base(raw, times, pick, T_base_lidar, velocity, some);
  for (std::size_t k = 0; k < pick.size(); ++k) EXPECT_TRUE(some[k].isApprox(out[pick[k]]));
  const std::vector<std::uint32_t> bad = {500};
  EXPECT_THROW(deskew_to_base(raw, times, bad, T_base_lidar, velocity, std::span(some).first(1)), std::invalid_argument);
}

// Oracle: deskewing with a wrong (predicted) velocity, then redeskew to the
// measured one, equals deskewing the raw points with the measured one directly.
TEST(Deskew, RedeskewEqualsDeskewingWithTheRefinedVelocity) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(-20.0, 20.0), when(-0.05, 0.05);
  BodyVelocity predicted, measured;
  predicted.linear = Vec3(1.2, 0.1, 0.0);
  predicted.angular = Vec3(0.0, 0.1, 0.5);
  measured.linear = Vec3(0.9, -0.3, 0.1);
  measured.angular = Vec3(0.2, -0.1, 0.8);
  const SE3 T_base_lidar(so3_exp(Vec3(0.7, 0.0, 0.1)), Vec3(0.0, -0.5, -0.2));
  std::vector<Eigen::Vector3f> raw;
  std::vector<float> times;
  for (int i = 0; i < 300; ++i) {
    raw.emplace_back(Vec3(coord(rng), coord(rng), coord(rng) / 4.0).cast<float>());
    times.push_back(static_cast<float>(when(rng)));
  }
  std::vector<Eigen::Vector3f> redeskewed(raw.size()), direct(raw.size());
  deskew_to_base(raw, times, {}, T_base_lidar, predicted, redeskewed);
  const std::vector<Eigen::Vector3f> before = redeskewed;
  redeskew(times, predicted, measured, redeskewed);
  deskew_to_base(raw, times, {}, T_base_lidar, measured, direct);
  double worst = 0.0, moved = 0.0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    worst = std::max(worst, static_cast<double>((redeskewed[i] - direct[i]).norm()));
    moved = std::max(moved, static_cast<double>((before[i] - direct[i]).norm()));
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(moved, 0.1);  // the two velocities differ enough to matter
  std::vector<Eigen::Vector3f> unchanged = before;
  redeskew({}, predicted, measured, unchanged);  // no times: no motion model to undo
  EXPECT_EQ(unchanged, before);
  EXPECT_THROW(redeskew(std::span(times).first(3), predicted, measured, unchanged), std::invalid_argument);
}

// The same oracle for a fast turn (sweep angles past the small-angle series) and for no rotation at all.
TEST(Deskew, RedeskewEqualsDeskewingDirectlyForFastAndNoRotation) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> coord(-20.0, 20.0), when(-0.05, 0.05);
  const SE3 T_base_lidar(so3_exp(Vec3(0.3, 0.2, -0.1)), Vec3(0.1, 0.2, 0.3));
  std::vector<Eigen::Vector3f> raw;
  std::vector<float> times;
  for (int i = 0; i < 300; ++i) {
    raw.emplace_back(Vec3(coord(rng), coord(rng), coord(rng) / 4.0).cast<float>());
    times.push_back(static_cast<float>(when(rng)));
  }
  BodyVelocity still, fast;
  still.linear = Vec3(2.0, 0.0, 0.0);  // angular zero
  fast.linear = Vec3(0.5, 1.0, 0.0);
  fast.angular = Vec3(1.0, -2.0, 9.0);  // up to 0.46 rad within +-0.05 s
  for (const auto& [from, to] : {std::pair{still, fast}, std::pair{fast, still}}) {
    std::vector<Eigen::Vector3f> redeskewed(raw.size()), direct(raw.size());
    deskew_to_base(raw, times, {}, T_base_lidar, from, redeskewed);
    redeskew(times, from, to, redeskewed);
    deskew_to_base(raw, times, {}, T_base_lidar, to, direct);
    for (std::size_t i = 0; i < raw.size(); ++i) ASSERT_LT((redeskewed[i] - direct[i]).norm(), 1e-4) << i;
  }
}

TEST(Deskew, VelocityFromRelativePoseRoundTrips) {
  const SE3 relative(so3_exp(Vec3(0.01, 0.02, 0.3)), Vec3(1.0, 0.2, -0.1));
  const BodyVelocity velocity = BodyVelocity::from_relative_pose(relative, 0.1);
  const SE3 back = velocity.pose_at(0.1);
  EXPECT_LT((back.translation() - relative.translation()).norm(), 1e-12);
  EXPECT_LT(so3_log(back.rotation().conjugate() * relative.rotation()).norm(), 1e-12);
}

}  // namespace
}  // namespace mlidar::slam
