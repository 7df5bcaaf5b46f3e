#include "mlidar/sim/lidar_models.hpp"

#include <algorithm>
#include <cmath>

#include "mlidar/core/error.hpp"

namespace mlidar::sim {
namespace {

/// count angles from first to last, evenly spaced.
std::vector<double> uniform_angles(double first, double last, int count) {
  std::vector<double> angles(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) angles[static_cast<std::size_t>(i)] = first + (last - first) * i / (count - 1);
  return angles;
}

/// HDL-64E: piecewise-linear approximation of the published table (S2 manual):
/// upper block 32 beams +2.0 .. -8.33 deg (1/3 deg step), lower block 32 beams
/// -8.83 .. -24.8 deg (26.8 deg total field of view as in the datasheet).
std::vector<double> hdl64_angles() {
  std::vector<double> angles = uniform_angles(2.0, -8.33, 32);
  const std::vector<double> lower = uniform_angles(-8.83, -24.8, 32);
  angles.insert(angles.end(), lower.begin(), lower.end());
  std::sort(angles.begin(), angles.end());
  return angles;
}

LidarModel make(const std::string& name, std::vector<double> angles, double horizontal_deg, double min_range, double max_range,
                double noise_sigma) {
  LidarModel model;
  model.name = name;
  model.vertical_angles_deg = std::move(angles);
  model.horizontal_resolution_deg = horizontal_deg;
  model.min_range = min_range;
  model.max_range = max_range;
  model.range_noise_sigma = noise_sigma;
  model.sweep_period = 0.1;
  return model;
}

}  // namespace

std::vector<std::string> lidar_model_names() { return {"VLP-16", "HDL-32E", "HDL-64E", "RS-LiDAR-16", "OS1-64", "OS0-64", "PandarQT"}; }

LidarModel lidar_model(const std::string& name) {
  // Datasheet figures at 10 Hz: elevation table, azimuth step, range limits, range accuracy (1 sigma).
  if (name == "VLP-16") return make(name, uniform_angles(-15.0, 15.0, 16), 0.2, 0.5, 100.0, 0.03);
  if (name == "HDL-32E") return make(name, uniform_angles(-30.67, 10.67, 32), 0.16, 1.0, 100.0, 0.02);
  if (name == "HDL-64E") return make(name, hdl64_angles(), 0.1728, 1.0, 120.0, 0.02);
  if (name == "RS-LiDAR-16") return make(name, uniform_angles(-15.0, 15.0, 16), 0.2, 0.4, 150.0, 0.03);
  if (name == "OS1-64") return make(name, uniform_angles(-16.6, 16.6, 64), 360.0 / 1024.0, 0.3, 120.0, 0.03);
  // Ouster OS0-64: 90 deg of uniform beams (the BALM keyframes' Ouster spans -45..45 deg), 1024 columns.
  if (name == "OS0-64") return make(name, uniform_angles(-45.0, 45.0, 64), 360.0 / 1024.0, 0.3, 100.0, 0.03);
  // Hesai PandarQT-like: 64 beams over a wide field of view, 600 columns, short range.
  if (name == "PandarQT") return make(name, uniform_angles(-52.1, 52.1, 64), 0.6, 0.1, 30.0, 0.03);
  std::string known;
  for (const auto& n : lidar_model_names()) known += (known.empty() ? "" : ", ") + n;
  throw UsageError("unknown LiDAR model '" + name + "' (known: " + known + ")");
}

int columns_per_sweep(const LidarModel& model) {
  return std::max(1, static_cast<int>(std::lround(360.0 / model.horizontal_resolution_deg)));
}

}  // namespace mlidar::sim
