#include <cstring>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/point_table.hpp"

namespace mlidar::io {
namespace {

TEST(PointTable, ScanRoundTripKeepsChannels) {
  Scan scan;
  scan.points = {{1.f, 2.f, 3.f}, {4.f, 5.f, 6.f}};
  scan.intensity = {10.f, 20.f};
  scan.ring = {0, 15};
  scan.time = {0.f, 0.05f};
  const Scan back = to_scan(from_scan(scan), "mem");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back.points[1], scan.points[1]);
  EXPECT_EQ(back.intensity, scan.intensity);
  EXPECT_EQ(back.ring, scan.ring);
  EXPECT_FLOAT_EQ(back.time[1], 0.05f);
}

TEST(PointTable, MissingXyzNamesTheField) {
  PointTable table;
  table.num_points = 1;
  table.add_field("x", ScalarType::kF32);
  table.add_field("y", ScalarType::kF32);
  try {
    to_scan(table, "cloud.pcd");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cloud.pcd: field z"), std::string::npos) << e.what();
  }
}

TEST(PointTable, DetectsNanosecondOffsets) {
  PointTable table;
  table.num_points = 3;
  for (const char* axis : {"x", "y", "z"}) table.add_field(axis, ScalarType::kF32);
  FieldColumn& t = table.add_field("t", ScalarType::kU32);
  const std::uint32_t ns[3] = {0, 50'000'000, 99'000'000};
  std::memcpy(t.data.data(), ns, sizeof(ns));
  const Scan scan = to_scan(table, "mem");
  EXPECT_NEAR(scan.time[2], 0.099, 1e-7);
}

}  // namespace
}  // namespace mlidar::io
