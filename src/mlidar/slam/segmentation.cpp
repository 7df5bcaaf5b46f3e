#include "mlidar/slam/segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace mlidar::slam {
namespace {

constexpr double kRadians = std::numbers::pi / 180.0;
constexpr std::int32_t kUnvisited = -2;

void label_ground(const RangeImage& image, std::span<const Eigen::Vector3f> points, const Eigen::Vector3f& up,
                  const SegmentationConfig& config, std::vector<std::int32_t>& label) {
  const float max_sin = static_cast<float>(std::sin(config.ground_slope_deg * kRadians));
  const float below = static_cast<float>(-config.ground_below_m);
  for (int row = 0; row + 1 < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) {
      const std::size_t lower = image.pixel(row, col);
      const std::size_t upper = image.pixel(row + 1, col);
      if (image.index[lower] == RangeImage::kEmpty || image.index[upper] == RangeImage::kEmpty) continue;
      const Eigen::Vector3f& a = points[static_cast<std::size_t>(image.index[lower])];
      const Eigen::Vector3f& b = points[static_cast<std::size_t>(image.index[upper])];
      if (a.dot(up) > below || b.dot(up) > below) continue;
      const Eigen::Vector3f step = b - a;
      const float length = step.norm();
      if (length > 0.0F && std::abs(step.dot(up)) <= max_sin * length) {
        label[lower] = Segmentation::kGround;
        label[upper] = Segmentation::kGround;
      }
    }
  }
}

/// Bogoslavskyi & Stachniss's criterion: beta > threshold, tested as
/// d2 sin(a) > tan(threshold) (d1 - d2 cos(a)) to avoid atan2 per pair.
bool same_object(float range_a, float range_b, double sin_step, double cos_step, double tan_threshold) {
  const double d1 = std::max(range_a, range_b);
  const double d2 = std::min(range_a, range_b);
  return d2 * sin_step > tan_threshold * (d1 - d2 * cos_step);
}

}  // namespace

void segment_range_image(const RangeImage& image, std::span<const Eigen::Vector3f> points, std::span<const double> sorted_angles_deg,
                         const Eigen::Vector3f& up_lidar, const SegmentationConfig& config, Segmentation& out) {
  if (sorted_angles_deg.size() != static_cast<std::size_t>(image.rows))
    throw std::invalid_argument("segment_range_image: angle table size differs from image rows");
  const std::size_t pixels = image.index.size();
  out.label.assign(pixels, kUnvisited);
  for (std::size_t p = 0; p < pixels; ++p)
    if (image.index[p] == RangeImage::kEmpty) out.label[p] = Segmentation::kNone;
  label_ground(image, points, up_lidar, config, out.label);

  const double tan_threshold = std::tan(config.angle_threshold_deg * kRadians);
  const double h_step = 2.0 * std::numbers::pi / image.cols;
  const double sin_h = std::sin(h_step);
  const double cos_h = std::cos(h_step);
  // The vertical step between row r and r + 1, once per row pair instead of once per pixel pair.
  std::vector<double> sin_up(static_cast<std::size_t>(std::max(image.rows - 1, 0)));
  std::vector<double> cos_up(sin_up.size());
  for (std::size_t r = 0; r < sin_up.size(); ++r) {
    const double v_step = std::abs(sorted_angles_deg[r + 1] - sorted_angles_deg[r]) * kRadians;
    sin_up[r] = std::sin(v_step);
    cos_up[r] = std::cos(v_step);
  }
  out.queue.resize(pixels);
  out.clusters = 0;
  const int cols = image.cols;
  for (int seed_row = 0; seed_row < image.rows; ++seed_row) {
    for (int seed_col = 0; seed_col < cols; ++seed_col) {
      const std::size_t seed = image.pixel(seed_row, seed_col);
      if (out.label[seed] != kUnvisited) continue;
      const std::int32_t id = out.clusters + 1;
      std::size_t head = 0;
      std::size_t tail = 0;
      out.queue[tail++] = {seed_row, seed_col};
      out.label[seed] = id;
      int min_row = image.rows;
      int max_row = -1;
      while (head < tail) {
        const auto [row, col] = out.queue[head++];
        const std::size_t p = image.pixel(row, col);
        min_row = std::min(min_row, row);
        max_row = std::max(max_row, row);
        const int neighbours[4][2] = {
            {row, col + 1 == cols ? 0 : col + 1}, {row, col == 0 ? cols - 1 : col - 1}, {row - 1, col}, {row + 1, col}};
        for (const auto& [nrow, ncol] : neighbours) {
          if (nrow < 0 || nrow >= image.rows) continue;
          const std::size_t q = image.pixel(nrow, ncol);
          if (out.label[q] != kUnvisited) continue;
          double sin_step = sin_h;
          double cos_step = cos_h;
          if (nrow != row) {
            const auto lower = static_cast<std::size_t>(std::min(nrow, row));
            sin_step = sin_up[lower];
            cos_step = cos_up[lower];
          }
          if (!same_object(image.range[p], image.range[q], sin_step, cos_step, tan_threshold)) continue;
          out.label[q] = id;
          out.queue[tail++] = {nrow, ncol};
        }
      }
      const bool large = static_cast<int>(tail) >= config.min_cluster_points;
      const bool tall = max_row - min_row + 1 >= config.min_cluster_rows && static_cast<int>(tail) >= config.min_row_span_points;
      if (large || tall) {
        ++out.clusters;
      } else {
        for (std::size_t k = 0; k < tail; ++k) out.label[image.pixel(out.queue[k][0], out.queue[k][1])] = Segmentation::kNone;
      }
    }
  }
}

}  // namespace mlidar::slam
