// Published vertical angle tables: ring count, span, ascending ring order.
#include <algorithm>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"
#include "mlidar/sim/lidar_models.hpp"

namespace mlidar::sim {
namespace {

struct Expected {
  const char* name;
  std::size_t rings;
  double lowest;
  double highest;
};

TEST(LidarModels, TablesMatchDatasheets) {
  const Expected table[] = {{"VLP-16", 16, -15.0, 15.0},      {"HDL-32E", 32, -30.67, 10.67}, {"HDL-64E", 64, -24.8, 2.0},
                            {"RS-LiDAR-16", 16, -15.0, 15.0}, {"OS1-64", 64, -16.6, 16.6},    {"OS0-64", 64, -45.0, 45.0},
                            {"PandarQT", 64, -52.1, 52.1}};
  for (const auto& e : table) {
    const LidarModel model = lidar_model(e.name);
    EXPECT_EQ(model.rings(), e.rings) << e.name;
    EXPECT_NEAR(model.vertical_angles_deg.front(), e.lowest, 1e-9) << e.name;
    EXPECT_NEAR(model.vertical_angles_deg.back(), e.highest, 1e-9) << e.name;
    EXPECT_TRUE(std::is_sorted(model.vertical_angles_deg.begin(), model.vertical_angles_deg.end())) << e.name;
    EXPECT_GT(columns_per_sweep(model), 500) << e.name;
  }
  EXPECT_NEAR(lidar_model("VLP-16").vertical_angles_deg[1], -13.0, 1e-12);
  EXPECT_EQ(columns_per_sweep(lidar_model("OS1-64")), 1024);
}

TEST(LidarModels, UnknownNameIsAUsageError) { EXPECT_THROW(lidar_model("VLP-17"), UsageError); }

}  // namespace
}  // namespace mlidar::sim
