// io::FrameSource: the one time rule, the pairing of files with frames, and
// the scans it skips, against datasets written by hand in each test.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/frame_source.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;
using io::ScalarType;

/// A cloud of `times.size()` points 5 m away along x (rows 0..n-1), with a time field `t` of `type` holding `times`.
io::PointTable cloud_with_times(const std::vector<double>& times, ScalarType type, bool with_ring = false, std::uint16_t ring = 0) {
  io::PointTable table;
  table.num_points = times.size();
  table.width = static_cast<std::uint32_t>(times.size());
  for (const char* axis : {"x", "y", "z"}) table.add_field(axis, ScalarType::kF32);
  io::FieldColumn& t = table.add_field("t", type);
  for (std::size_t i = 0; i < times.size(); ++i) {
    const float xyz[3] = {5.0F, 0.01F * static_cast<float>(i), 0.0F};
    for (int a = 0; a < 3; ++a) std::memcpy(table.fields[static_cast<std::size_t>(a)].data.data() + 4 * i, &xyz[a], 4);
    std::byte* out = t.data.data() + i * io::scalar_size(type);
    switch (type) {
      case ScalarType::kF64: {
        const double v = times[i];
        std::memcpy(out, &v, 8);
        break;
      }
      case ScalarType::kF32: {
        const float v = static_cast<float>(times[i]);
        std::memcpy(out, &v, 4);
        break;
      }
      case ScalarType::kU32: {
        const auto v = static_cast<std::uint32_t>(times[i]);
        std::memcpy(out, &v, 4);
        break;
      }
      case ScalarType::kU8: {
        const auto v = static_cast<std::uint8_t>(times[i]);
        std::memcpy(out, &v, 1);
        break;
      }
      default:
        ADD_FAILURE() << "type not used by these tests";
    }
  }
  if (with_ring) {
    io::FieldColumn& r = table.add_field("ring", ScalarType::kU16);
    for (std::size_t i = 0; i < times.size(); ++i) std::memcpy(r.data.data() + 2 * i, &ring, 2);
  }
  return table;
}

void write_pcd(const fs::path& path, io::PointTable table) {
  io::CloudFile cloud;
  cloud.table = std::move(table);
  io::write_cloud(path, cloud);
}

/// A one-LiDAR dataset "top" (rows at -1 and 1 deg, ranges 0.5-100 m) with `stamps` and no clouds yet.
fs::path one_lidar_dataset(const fs::path& dir, const std::vector<double>& stamps, const std::string& extra = "", double min_range = 0.5) {
  fs::create_directories(dir / "scans/top");
  std::ofstream(dir / "dataset.yaml") << "name: t\nframe_period: 0.1\nbase: top\nlidars:\n"
                                         "  - {name: top, model: m, scans: scans/top, vertical_angles_deg: [-1, 1], min_range: "
                                      << min_range << ", max_range: 100" << extra << "}\n";
  std::ofstream times(dir / "times.txt");
  for (const double s : stamps) times << s << '\n';
  return dir;
}

std::string frame_file(int k) {
  char name[16];
  std::snprintf(name, sizeof name, "%06d.pcd", k);
  return name;
}

TEST(FrameSource, RelativeSecondsCountFromTheFrameStampAndMayBeNegative) {
  const fs::path dir = one_lidar_dataset(scratch_dir(), {10.0, 10.1});
  write_pcd(dir / "scans/top" / frame_file(0), cloud_with_times({0.0, 0.05, 0.099}, ScalarType::kF64));
  write_pcd(dir / "scans/top" / frame_file(1), cloud_with_times({-0.1, -0.04, 0.0}, ScalarType::kF32));  // stamped at the sweep's end
  const io::FrameSource source = io::FrameSource::dataset(dir);
  const io::SourceFrame first = source.read(0);
  ASSERT_TRUE(first.scans[0]);
  EXPECT_DOUBLE_EQ(first.scans[0]->stamp, 10.0);
  EXPECT_FLOAT_EQ(first.scans[0]->time[2], 0.099F);
  const io::SourceFrame second = source.read(1);
  ASSERT_TRUE(second.scans[0]);
  EXPECT_NEAR(second.scans[0]->stamp, 10.1 - 0.1, 1e-7);  // the earliest point, float32 -0.1
  EXPECT_NEAR(second.scans[0]->time[1], 0.06, 1e-6);
  EXPECT_TRUE(first.skipped.empty());
}

TEST(FrameSource, IntegerTimesAreNanosecondsAndAbsoluteTimesUseTheirOwnClock) {
  const fs::path dir = one_lidar_dataset(scratch_dir(), {1700000000.0});
  // Ouster-style uint32 nanoseconds from the sweep start: 50 ms = 5e7 ns.
  write_pcd(dir / "scans/top" / frame_file(0), cloud_with_times({0.0, 5e7, 9e7}, ScalarType::kU32));
  const Scan relative = *io::FrameSource::dataset(dir).read(0).scans[0];
  EXPECT_DOUBLE_EQ(relative.stamp, 1700000000.0);
  EXPECT_NEAR(relative.time[1], 0.05, 1e-9);
  // Hesai-style float64 unix seconds, the sweep starting 20 ms after the frame stamp.
  write_pcd(dir / "scans/top" / frame_file(0), cloud_with_times({1700000000.02, 1700000000.07}, ScalarType::kF64));
  const Scan absolute = *io::FrameSource::dataset(dir).read(0).scans[0];
  EXPECT_NEAR(absolute.stamp - 1700000000.0, 0.02, 1e-6);
  EXPECT_NEAR(absolute.time[1], 0.05, 1e-6);
}

TEST(FrameSource, AFolderOfCloudsHasNoClockSoAbsoluteTimesStartAtTheFrame) {
  const fs::path dir = scratch_dir();
  write_pcd(dir / "a1.pcd", cloud_with_times({1700000000.02, 1700000000.07}, ScalarType::kF64));
  write_pcd(dir / "a2.pcd", cloud_with_times({1700000000.52, 1700000000.57}, ScalarType::kF64));
  const io::FrameSource source = io::FrameSource::scan_folder(dir, 0.5);
  ASSERT_EQ(source.frames(), 2U);
  EXPECT_DOUBLE_EQ(source.read(1).scans[0]->stamp, 0.5);
  EXPECT_NEAR(source.read(1).scans[0]->time[1], 0.05, 1e-6);
}

TEST(FrameSource, TimesOutsideTheFramesPeriodsAreAnErrorNamingFileAndField) {
  const fs::path dir = one_lidar_dataset(scratch_dir(), {0.0});
  const fs::path file = dir / "scans/top" / frame_file(0);
  for (const auto& times : {std::vector<double>{0.0, 10.0}, std::vector<double>{-5.0, -4.95}, std::vector<double>{0.25, 0.3}}) {
    write_pcd(file, cloud_with_times(times, ScalarType::kF64));
    try {
      io::FrameSource::dataset(dir).read(0);
      ADD_FAILURE() << "accepted times " << times.front() << " .. " << times.back();
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file.string());
      EXPECT_EQ(e.field(), "field t");
      EXPECT_NE(std::string(e.what()).find("[-1, 2] frame periods"), std::string::npos) << e.what();
    }
  }
  write_pcd(file, cloud_with_times({0.0, 1.0, 2.0}, ScalarType::kU8));  // 8 bits cannot hold a time
  try {
    io::FrameSource::dataset(dir).read(0);
    ADD_FAILURE() << "accepted a uint8 time field";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file.string());
    EXPECT_NE(std::string(e.what()).find("uint8, which cannot hold a per-point time"), std::string::npos) << e.what();
  }
  // ...unless dataset.yaml says which unit it holds (here milliseconds).
  one_lidar_dataset(dir, {0.0}, ", time_unit: ms");
  EXPECT_NEAR(io::FrameSource::dataset(dir).read(0).scans[0]->time[2], 0.002, 1e-9);
  write_pcd(file, cloud_with_times({0.0, NAN}, ScalarType::kF64));
  EXPECT_THROW(io::FrameSource::dataset(dir).read(0), InputError);
}

TEST(FrameSource, UnusableScansAreSkippedWithTheirReason) {
  const fs::path dir = one_lidar_dataset(scratch_dir(), {0.0, 0.1, 0.2, 0.3, 0.4});
  write_pcd(dir / "scans/top" / frame_file(0), cloud_with_times({0.0, 0.01}, ScalarType::kF64));
  write_pcd(dir / "scans/top" / frame_file(1), cloud_with_times({}, ScalarType::kF64));  // empty
  io::PointTable nan_cloud = cloud_with_times({0.0}, ScalarType::kF64);
  const float nan = NAN;
  std::memcpy(nan_cloud.fields[0].data.data(), &nan, 4);
  write_pcd(dir / "scans/top" / frame_file(2), nan_cloud);
  write_pcd(dir / "scans/top" / frame_file(3), cloud_with_times({0.0, 0.01}, ScalarType::kF64, true, 7));  // rings 7 of a 2-row model
  const io::FrameSource source = io::FrameSource::dataset(dir);                                            // frame 4 has no file: missing
  const std::vector<io::ScanGap> expected = {io::ScanGap::kEmpty, io::ScanGap::kNoFinitePoint, io::ScanGap::kNoUsablePoint,
                                             io::ScanGap::kMissing};
  EXPECT_TRUE(source.read(0).scans[0].has_value());
  for (std::size_t k = 1; k < 5; ++k) {
    const io::SourceFrame frame = source.read(k);
    EXPECT_FALSE(frame.scans[0].has_value()) << k;
    ASSERT_EQ(frame.skipped.size(), 1U) << k;
    EXPECT_EQ(frame.skipped[0].frame, k);
    EXPECT_EQ(frame.skipped[0].reason, expected[k - 1]) << k;
  }
  EXPECT_NE(source.read(3).skipped[0].detail.find("ring values 7-7 beyond the model's 2 rows"), std::string::npos)
      << source.read(3).skipped[0].detail;
  EXPECT_TRUE(source.read(4).skipped[0].file.empty());
}

TEST(FrameSource, PointsOutsideTheRangeMakeAScanUnusable) {
  const fs::path dir = one_lidar_dataset(scratch_dir(), {0.0}, "", 10.0);  // every point is 5 m away
  write_pcd(dir / "scans/top" / frame_file(0), cloud_with_times({0.0, 0.01}, ScalarType::kF64));
  const io::SourceFrame frame = io::FrameSource::dataset(dir).read(0);
  ASSERT_EQ(frame.skipped.size(), 1U);
  EXPECT_EQ(frame.skipped[0].reason, io::ScanGap::kNoUsablePoint);
  EXPECT_NE(frame.skipped[0].detail.find("no point between min_range 10 m and max_range 100 m"), std::string::npos)
      << frame.skipped[0].detail;
}

TEST(FrameSource, StampCountsMustMatchTheClouds) {
  const fs::path dir = one_lidar_dataset(scratch_dir(), {});
  write_pcd(dir / "scans/top" / frame_file(0), cloud_with_times({0.0}, ScalarType::kF64));
  try {
    io::FrameSource::dataset(dir);
    ADD_FAILURE() << "accepted an empty times.txt";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), (dir / "times.txt").string());
    EXPECT_NE(std::string(e.what()).find("holds no stamp"), std::string::npos) << e.what();
  }
  one_lidar_dataset(dir, {0.0});
  write_pcd(dir / "scans/top" / frame_file(1), cloud_with_times({0.0}, ScalarType::kF64));
  try {
    io::FrameSource::dataset(dir);
    ADD_FAILURE() << "accepted 2 clouds for 1 stamp";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("2 clouds for 1 stamps in " + (dir / "times.txt").string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::FrameSource::dataset(dir, std::vector<std::string>{"front"}), UsageError);
}

}  // namespace
}  // namespace mlidar::test
