#include "mlidar/detect/bev_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mlidar::detect {
namespace {

int cells(double from, double to, double cell) { return static_cast<int>(std::ceil((to - from) / cell - 1e-9)); }

/// Running sums of one pillar.
struct Pillar {
  double x = 0.0, y = 0.0, z = 0.0, intensity = 0.0, uncertainty = 0.0;
  double max_z = -std::numeric_limits<double>::infinity();
  double min_z = std::numeric_limits<double>::infinity();
  std::uint32_t count = 0;
};

}  // namespace

std::optional<std::pair<int, int>> BevGrid::cell_of(double x, double y, const BevGridConfig& config) {
  if (!(x >= config.x_min && x < config.x_max && y >= config.y_min && y < config.y_max)) return std::nullopt;
  const int col = std::min(static_cast<int>((x - config.x_min) / config.cell), cells(config.x_min, config.x_max, config.cell) - 1);
  const int row = std::min(static_cast<int>((y - config.y_min) / config.cell), cells(config.y_min, config.y_max, config.cell) - 1);
  return std::pair{row, col};
}

BevGrid make_bev_grid(std::span<const Vec3> points, std::span<const float> intensity, std::span<const double> uncertainty,
                      const BevGridConfig& config) {
  if ((!intensity.empty() && intensity.size() != points.size()) || (!uncertainty.empty() && uncertainty.size() != points.size()))
    throw std::invalid_argument("make_bev_grid: one intensity and one uncertainty per point, or none");
  if (!(config.cell > 0.0) || !(config.x_max > config.x_min) || !(config.y_max > config.y_min) || !(config.z_max > config.z_min))
    throw std::invalid_argument("make_bev_grid: the grid needs a positive cell and ranges with max > min");
  BevGrid grid;
  grid.rows = cells(config.y_min, config.y_max, config.cell);
  grid.cols = cells(config.x_min, config.x_max, config.cell);
  const std::size_t area = static_cast<std::size_t>(grid.rows) * grid.cols;
  std::vector<Pillar> pillars(area);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    if (!(p.z() >= config.z_min && p.z() < config.z_max)) continue;  // also drops NaN
    const auto cell = BevGrid::cell_of(p.x(), p.y(), config);
    if (!cell) continue;
    Pillar& pillar = pillars[static_cast<std::size_t>(cell->first) * grid.cols + cell->second];
    pillar.x += p.x();
    pillar.y += p.y();
    pillar.z += p.z();
    pillar.intensity += intensity.empty() ? 0.0 : intensity[i];
    pillar.uncertainty += uncertainty.empty() ? 0.0 : uncertainty[i];
    pillar.max_z = std::max(pillar.max_z, p.z());
    pillar.min_z = std::min(pillar.min_z, p.z());
    ++pillar.count;
  }
  grid.features.assign(kBevChannels * area, 0.0f);
  grid.counts.assign(area, 0);
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      const std::size_t k = static_cast<std::size_t>(row) * grid.cols + col;
      const Pillar& pillar = pillars[k];
      if (pillar.count == 0) continue;
      const double n = pillar.count;
      const double centre_x = config.x_min + (col + 0.5) * config.cell, centre_y = config.y_min + (row + 0.5) * config.cell;
      const double values[kBevChannels] = {pillar.x / n - centre_x, pillar.y / n - centre_y, pillar.z / n, pillar.max_z,
                                           pillar.min_z, pillar.intensity / n, pillar.uncertainty / n, std::log1p(n)};
      for (int channel = 0; channel < kBevChannels; ++channel) grid.features[channel * area + k] = static_cast<float>(values[channel]);
      grid.counts[k] = pillar.count;
    }
  }
  return grid;
}

}  // namespace mlidar::detect
