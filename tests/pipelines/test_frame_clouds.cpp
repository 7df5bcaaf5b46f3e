// frame_clouds: the rule that pairs a LiDAR's cloud files with frames when
// some scans are missing (files named by frame number), and its errors.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/io/cloud_files.hpp"
#include "test_support.hpp"

namespace mlidar::test {
namespace {

namespace fs = std::filesystem;

void touch(const fs::path& path) { std::ofstream(path) << "x"; }

TEST(FrameClouds, AsManyCloudsAsFramesPairInNaturalOrder) {
  const fs::path dir = scratch_dir();
  for (const char* name : {"scan2.pcd", "scan10.pcd", "scan1.pcd"}) touch(dir / name);
  const auto clouds = io::frame_clouds(dir, 3);
  ASSERT_EQ(clouds.size(), 3U);
  EXPECT_EQ(clouds[0]->filename(), "scan1.pcd");
  EXPECT_EQ(clouds[1]->filename(), "scan2.pcd");
  EXPECT_EQ(clouds[2]->filename(), "scan10.pcd");
}

TEST(FrameClouds, FewerCloudsArePlacedByTheirFrameNumber) {
  const fs::path dir = scratch_dir();
  for (const char* name : {"000000.pcd", "000001.pcd", "000004.pcd"}) touch(dir / name);
  const auto clouds = io::frame_clouds(dir, 5);
  ASSERT_EQ(clouds.size(), 5U);
  EXPECT_EQ(clouds[1]->filename(), "000001.pcd");
  EXPECT_FALSE(clouds[2].has_value());
  EXPECT_FALSE(clouds[3].has_value());
  EXPECT_EQ(clouds[4]->filename(), "000004.pcd");
}

TEST(FrameClouds, FewerCloudsWithoutFrameNumbersAreAnError) {
  const fs::path dir = scratch_dir();
  touch(dir / "a.pcd");
  touch(dir / "000009.pcd");
  try {
    io::frame_clouds(dir, 5);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame number"), std::string::npos) << e.what();
  }
  fs::remove(dir / "a.pcd");
  EXPECT_THROW(io::frame_clouds(dir, 5), InputError);  // 9 is no frame of 5
  fs::remove(dir / "000009.pcd");
  touch(dir / "1.pcd");
  touch(dir / "001.ply");
  EXPECT_THROW(io::frame_clouds(dir, 5), InputError);  // two files for frame 1
}

TEST(FrameClouds, MoreCloudsThanStampsAreAnErrorNamingTheStamps) {
  // 20 clouds for 19 stamps used to drop the last cloud silently.
  const fs::path dir = scratch_dir();
  for (int k = 0; k < 4; ++k) touch(dir / ("00000" + std::to_string(k) + ".pcd"));
  try {
    io::frame_clouds(dir, 3, "DATA/times.txt");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("4 clouds for 3 stamps in DATA/times.txt"), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::frame_clouds(dir, 0), InputError);  // an empty times.txt
}

}  // namespace
}  // namespace mlidar::test
