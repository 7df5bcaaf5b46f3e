#include "mlidar/sim/uniform_grid.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace mlidar::sim {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr long kMaxCells = 4'000'000;
}  // namespace

UniformGrid::UniformGrid(std::vector<Primitive> primitives, double cell_size) : primitives_(std::move(primitives)), cell_size_(cell_size) {
  assert(cell_size > 0.0);
  if (primitives_.empty()) return;
  min_ = Vec3::Constant(kInf);
  max_ = Vec3::Constant(-kInf);
  for (const auto& p : primitives_) {
    assert(is_bounded(p));
    const Bounds b = bounds(p);
    min_ = min_.cwiseMin(b.min);
    max_ = max_.cwiseMax(b.max);
  }
  // Grow cells until the grid stays small enough.
  auto cells_along = [&](int axis) { return std::max(1L, static_cast<long>(std::ceil((max_[axis] - min_[axis]) / cell_size_))); };
  while (cells_along(0) * cells_along(1) > kMaxCells) cell_size_ *= 2.0;
  nx_ = static_cast<int>(cells_along(0));
  ny_ = static_cast<int>(cells_along(1));

  auto cell_range = [&](const Bounds& b, int& x0, int& x1, int& y0, int& y1) {
    x0 = std::clamp(static_cast<int>(std::floor((b.min.x() - min_.x()) / cell_size_)), 0, nx_ - 1);
    x1 = std::clamp(static_cast<int>(std::floor((b.max.x() - min_.x()) / cell_size_)), 0, nx_ - 1);
    y0 = std::clamp(static_cast<int>(std::floor((b.min.y() - min_.y()) / cell_size_)), 0, ny_ - 1);
    y1 = std::clamp(static_cast<int>(std::floor((b.max.y() - min_.y()) / cell_size_)), 0, ny_ - 1);
  };
  // Two passes: count per cell, then fill (compressed sparse rows).
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
  for (const auto& p : primitives_) {
    int x0, x1, y0, y1;
    cell_range(bounds(p), x0, x1, y0, y1);
    for (int iy = y0; iy <= y1; ++iy)
      for (int ix = x0; ix <= x1; ++ix) ++counts[static_cast<std::size_t>(cell_index(ix, iy)) + 1];
  }
  for (std::size_t i = 1; i < counts.size(); ++i) counts[i] += counts[i - 1];
  cell_start_ = counts;
  cell_items_.resize(counts.back());
  for (std::uint32_t index = 0; index < primitives_.size(); ++index) {
    int x0, x1, y0, y1;
    cell_range(bounds(primitives_[index]), x0, x1, y0, y1);
    for (int iy = y0; iy <= y1; ++iy)
      for (int ix = x0; ix <= x1; ++ix) cell_items_[counts[static_cast<std::size_t>(cell_index(ix, iy))]++] = index;
  }
}

bool UniformGrid::clip(const Ray& ray, double& t0, double& t1) const {
  for (int a = 0; a < 3; ++a) {
    const double d = ray.direction[a];
    if (d == 0.0) {
      if (ray.origin[a] < min_[a] || ray.origin[a] > max_[a]) return false;
      continue;
    }
    double ta = (min_[a] - ray.origin[a]) / d;
    double tb = (max_[a] - ray.origin[a]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

std::optional<Hit> UniformGrid::cast(const Ray& ray, double t_min, double t_max) const {
  if (primitives_.empty()) return std::nullopt;
  double t0 = t_min;
  double t1 = t_max;
  if (!clip(ray, t0, t1)) return std::nullopt;

  const Vec3 entry = ray.origin + t0 * ray.direction;
  int ix = std::clamp(static_cast<int>(std::floor((entry.x() - min_.x()) / cell_size_)), 0, nx_ - 1);
  int iy = std::clamp(static_cast<int>(std::floor((entry.y() - min_.y()) / cell_size_)), 0, ny_ - 1);
  const double dx = ray.direction.x();
  const double dy = ray.direction.y();
  const int step_x = dx > 0.0 ? 1 : -1;
  const int step_y = dy > 0.0 ? 1 : -1;
  const double delta_x = dx != 0.0 ? cell_size_ / std::abs(dx) : kInf;
  const double delta_y = dy != 0.0 ? cell_size_ / std::abs(dy) : kInf;
  double next_x = dx != 0.0 ? (min_.x() + (ix + (step_x > 0 ? 1 : 0)) * cell_size_ - ray.origin.x()) / dx : kInf;
  double next_y = dy != 0.0 ? (min_.y() + (iy + (step_y > 0 ? 1 : 0)) * cell_size_ - ray.origin.y()) / dy : kInf;

  std::optional<Hit> best;
  double limit = t_max;
  while (true) {
    const auto cell = static_cast<std::size_t>(cell_index(ix, iy));
    for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
      auto hit = intersect(primitives_[cell_items_[k]], ray, t_min, limit);
      if (hit) {
        limit = hit->t;
        best = hit;
      }
    }
    const double cell_exit = std::min(next_x, next_y);
    if ((best && best->t <= cell_exit) || cell_exit > t1) break;
    if (next_x < next_y) {
      ix += step_x;
      next_x += delta_x;
      if (ix < 0 || ix >= nx_) break;
    } else {
      iy += step_y;
      next_y += delta_y;
      if (iy < 0 || iy >= ny_) break;
    }
  }
  return best;
}

}  // namespace mlidar::sim
