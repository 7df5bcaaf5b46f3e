#pragma once
// Spinning LiDAR models with their published vertical angle tables.
// Ring index = position in the table sorted by elevation ascending (ring 0 is
// the lowest beam), whatever the firing order of the real sensor.
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::sim {

/// Names accepted by lidar_model(): "VLP-16", "HDL-32E", "HDL-64E",
/// "RS-LiDAR-16", "OS1-64", "OS0-64", "PandarQT".
std::vector<std::string> lidar_model_names();

/// The named model; throws UsageError listing the known names otherwise.
LidarModel lidar_model(const std::string& name);

/// Columns (firings) per revolution: round(360 / horizontal_resolution_deg).
int columns_per_sweep(const LidarModel& model);

}  // namespace mlidar::sim
