#include "mlidar/slam/range_image.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace mlidar::slam {

int nearest_row(std::span<const double> sorted_angles_deg, double elevation_deg) {
  const auto upper = std::lower_bound(sorted_angles_deg.begin(), sorted_angles_deg.end(), elevation_deg);
  if (upper == sorted_angles_deg.begin()) return 0;
  if (upper == sorted_angles_deg.end()) return static_cast<int>(sorted_angles_deg.size()) - 1;
  const auto lower = upper - 1;
  const auto row = (elevation_deg - *lower <= *upper - elevation_deg) ? lower : upper;
  return static_cast<int>(row - sorted_angles_deg.begin());
}

namespace {

/// std::lround of a column coordinate (|x| < 2^31) without the library call: halves away from zero, exactly
/// (x minus its truncation is exact in double).
int round_half_away(double x) {
  const auto whole = static_cast<int>(x);
  const double fraction = x - static_cast<double>(whole);
  return whole + static_cast<int>(fraction >= 0.5) - static_cast<int>(fraction <= -0.5);
}

}  // namespace

double fast_atan2(double y, double x) {
  const double ax = std::abs(x);
  const double ay = std::abs(y);
  const double big = std::max(ax, ay);
  if (big == 0.0) return 0.0;
  const double t = std::min(ax, ay) / big;  // in [0, 1]
  const double t2 = t * t;
  // A&S 4.4.49: atan t = t (1 + a2 t^2 + a4 t^4 + ... + a16 t^16).
  double poly = 0.0028662257;
  poly = poly * t2 - 0.0161657367;
  poly = poly * t2 + 0.0429096138;
  poly = poly * t2 - 0.0752896400;
  poly = poly * t2 + 0.1065626393;
  poly = poly * t2 - 0.1420889944;
  poly = poly * t2 + 0.1999355085;
  poly = poly * t2 - 0.3333314528;
  double angle = t * (1.0 + poly * t2);
  if (ay > ax) angle = std::numbers::pi / 2.0 - angle;
  if (x < 0.0) angle = std::numbers::pi - angle;
  return std::signbit(y) ? -angle : angle;
}

void build_range_image(std::span<const Eigen::Vector3f> points, std::span<const std::uint16_t> ring, const LidarModel& model,
                       RangeImage& image) {
  if (model.vertical_angles_deg.empty() || !(model.horizontal_resolution_deg > 0.0))
    throw std::invalid_argument("build_range_image: model '" + model.name + "' has no vertical angles or resolution");
  if (!ring.empty() && ring.size() != points.size()) throw std::invalid_argument("build_range_image: ring size differs from points");
  std::vector<double> sorted = model.vertical_angles_deg;  // rings() entries, small
  std::sort(sorted.begin(), sorted.end());
  image.rows = static_cast<int>(sorted.size());
  image.cols = std::max(1, static_cast<int>(std::lround(360.0 / model.horizontal_resolution_deg)));
  const std::size_t pixels = static_cast<std::size_t>(image.rows) * static_cast<std::size_t>(image.cols);
  image.range.assign(pixels, 0.0F);
  image.index.assign(pixels, RangeImage::kEmpty);
  const double degrees = 180.0 / std::numbers::pi;
  const double cols_per_degree = 1.0 / model.horizontal_resolution_deg;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    const double range = p.cast<double>().norm();
    if (range < model.min_range || range > model.max_range) continue;
    int row = 0;
    if (!ring.empty()) {
      if (ring[i] >= image.rows) continue;
      row = ring[i];
    } else {
      row = nearest_row(sorted, std::asin(std::clamp(static_cast<double>(p.z()) / range, -1.0, 1.0)) * degrees);
    }
    // Clockwise azimuth, the firing order of spinning sensors (sim/acquisition.hpp).
    const double azimuth_deg = -fast_atan2(static_cast<double>(p.y()), static_cast<double>(p.x())) * degrees;
    int col = round_half_away(azimuth_deg * cols_per_degree);
    if (col < 0 || col >= image.cols) {  // one turn either way at most: the azimuth is within half a turn
      col %= image.cols;
      if (col < 0) col += image.cols;
    }
    const std::size_t pixel = image.pixel(row, col);
    if (image.index[pixel] == RangeImage::kEmpty || range < image.range[pixel]) {
      image.range[pixel] = static_cast<float>(range);
      image.index[pixel] = static_cast<std::int32_t>(i);
    }
  }
}

}  // namespace mlidar::slam
