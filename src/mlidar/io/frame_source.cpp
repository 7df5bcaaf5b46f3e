#include "mlidar/io/frame_source.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mlidar/core/error.hpp"
#include "mlidar/core/median.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/cloud_files.hpp"

namespace mlidar::io {
namespace {

/// Times beyond this many seconds are absolute (unix) times: 1e6 s is 11.6 days after 1970.
constexpr double kAbsoluteTimeSeconds = 1e6;
/// Point times must lie within [kEarliestPeriods, kLatestPeriods] frame periods of the frame stamp.
constexpr double kEarliestPeriods = -1.0;
constexpr double kLatestPeriods = 2.0;
/// Slack on those bounds for times stored as float32 (-0.1 s is -0.100000001).
constexpr double kBoundSlackSeconds = 1e-6;

std::string seconds_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

/// Points a front end can use: inside [min_range, max_range] and, when the scan has rings and the model
/// rows, below the row count. Empty when some are; otherwise why none is.
std::string why_unusable(const Scan& scan, const LidarModel& model) {
  const bool check_rings = scan.has_ring() && model.rings() > 0;
  double nearest = INFINITY, farthest = 0.0;
  std::uint16_t ring_lo = UINT16_MAX, ring_hi = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double range = scan.points[i].cast<double>().norm();
    const bool in_range = range >= model.min_range && range <= model.max_range;
    const bool in_rows = !check_rings || scan.ring[i] < model.rings();
    if (in_range && in_rows) return {};
    nearest = std::min(nearest, range);
    farthest = std::max(farthest, range);
    if (check_rings) {
      ring_lo = std::min(ring_lo, scan.ring[i]);
      ring_hi = std::max(ring_hi, scan.ring[i]);
    }
  }
  if (check_rings && ring_lo >= model.rings())
    return "ring values " + std::to_string(ring_lo) + "-" + std::to_string(ring_hi) + " beyond the model's " +
           std::to_string(model.rings()) + " rows (vertical_angles_deg in dataset.yaml)";
  return "no point between min_range " + seconds_text(model.min_range) + " m and max_range " + seconds_text(model.max_range) +
         " m (points lie " + seconds_text(nearest) + " to " + seconds_text(farthest) + " m away)";
}

/// Clouds from files: [lidar][frame] paths.
class FileClouds final : public CloudProvider {
 public:
  explicit FileClouds(std::vector<std::vector<std::optional<std::filesystem::path>>> files) : files_(std::move(files)) {}
  std::optional<PointTable> cloud(std::size_t k, std::size_t j, std::string& name) const override {
    const std::optional<std::filesystem::path>& path = files_[j][k];
    if (!path) return std::nullopt;
    name = path->string();
    return read_cloud(*path).table;
  }

 private:
  std::vector<std::vector<std::optional<std::filesystem::path>>> files_;
};

/// The median of the gaps between consecutive stamps; none for fewer than two.
std::optional<double> median_gap(const std::vector<double>& stamps) {
  if (stamps.size() < 2) return std::nullopt;
  std::vector<double> gaps;
  for (std::size_t k = 1; k < stamps.size(); ++k) gaps.push_back(stamps[k] - stamps[k - 1]);
  return upper_median(std::move(gaps));  // as a bag's period (bag_frames.cpp)
}

}  // namespace

const char* to_string(ScanGap gap) {
  switch (gap) {
    case ScanGap::kMissing:
      return "missing";
    case ScanGap::kEmpty:
      return "empty";
    case ScanGap::kNoFinitePoint:
      return "all_nan";
    case ScanGap::kNoUsablePoint:
      return "no_usable_point";
  }
  return "unknown";
}

FrameSource FrameSource::dataset(const std::filesystem::path& folder, std::span<const std::string> lidars) {
  FrameSource source;
  source.dataset_ = read_dataset_yaml(folder);
  const Dataset& dataset = *source.dataset_;
  const std::filesystem::path times = folder / dataset.times;
  source.stamps_ = read_times(times);
  if (source.stamps_.empty()) throw InputError(times.string(), "stamps", "holds no stamp (one line per frame, seconds)");
  source.period_ = dataset.frame_period;
  for (const std::string& name : lidars) {
    if (std::none_of(dataset.lidars.begin(), dataset.lidars.end(), [&](const auto& l) { return l.name == name; }))
      throw UsageError("--lidars: no LiDAR '" + name + "' in " + (folder / "dataset.yaml").string());
  }
  std::vector<std::vector<std::optional<std::filesystem::path>>> files;
  for (const DatasetLidar& lidar : dataset.lidars) {
    if (!lidars.empty() && std::find(lidars.begin(), lidars.end(), lidar.name) == lidars.end()) continue;
    source.lidars_.push_back({lidar.name, lidar.model, lidar.initial_extrinsic, lidar.time_unit, folder / lidar.scans});
    files.push_back(frame_clouds(source.lidars_.back().folder, source.stamps_.size(), times.string()));
  }
  source.clouds_ = std::make_shared<FileClouds>(std::move(files));
  return source;
}

FrameSource FrameSource::scan_folder(const std::filesystem::path& folder, double period, const std::optional<std::filesystem::path>& times,
                                     const LidarModel& model) {
  if (!(period > 0.0) || !std::isfinite(period)) throw UsageError("--period: expected a finite number of seconds > 0");
  FrameSource source;
  source.period_ = period;
  source.own_clock_ = times.has_value();
  source.lidars_.push_back({"lidar", model, std::nullopt, TimeUnit::kAuto, folder});
  std::vector<std::vector<std::optional<std::filesystem::path>>> files(1);
  for (const auto& cloud : natural_sorted_clouds(folder)) {
    source.stamps_.push_back(static_cast<double>(source.stamps_.size()) * period);
    files[0].push_back(cloud);
  }
  if (times) {
    std::vector<double> stamps = read_times(*times);
    if (stamps.size() != source.stamps_.size())
      throw InputError(times->string(), "stamps",
                       std::to_string(stamps.size()) + " stamps for " + std::to_string(source.stamps_.size()) + " clouds in " +
                           folder.string() + ": give one stamp per cloud, in the clouds' natural order");
    source.period_ = median_gap(stamps).value_or(period);
    source.stamps_ = std::move(stamps);
  }
  source.clouds_ = std::make_shared<FileClouds>(std::move(files));
  return source;
}

std::optional<std::size_t> FrameSource::find(const std::string& name) const {
  for (std::size_t j = 0; j < lidars_.size(); ++j)
    if (lidars_[j].name == name) return j;
  return std::nullopt;
}

std::optional<std::size_t> FrameSource::reference_index() const {
  if (!dataset_) return 0;
  return find(dataset_->reference_lidar.empty() ? dataset_->base : dataset_->reference_lidar);
}

std::optional<Scan> FrameSource::load(std::size_t k, std::size_t j, SkippedScan& gap) const {
  gap = {k, j, ScanGap::kMissing, {}, {}};
  const std::optional<PointTable> table = clouds_->cloud(k, j, gap.file);
  if (!table) return std::nullopt;
  if (table->num_points == 0) {
    gap.reason = ScanGap::kEmpty;
    return std::nullopt;
  }
  const SourceLidar& lidar = lidars_[j];
  Scan scan = to_scan(*table, gap.file, ScanOptions{.time_unit = lidar.time_unit});
  if (scan.empty()) {
    gap.reason = ScanGap::kNoFinitePoint;
    gap.detail = std::to_string(table->num_points) + " points, none with finite x, y and z";
    return std::nullopt;
  }
  const double frame_stamp = stamps_[k];
  const double origin = scan.stamp;  // the earliest point's time as the field holds it (0 without a time field)
  const bool absolute = std::abs(origin) > kAbsoluteTimeSeconds;
  scan.stamp = absolute ? (own_clock_ ? origin : frame_stamp) : frame_stamp + origin;
  if (scan.has_time()) {
    const double first = scan.stamp - frame_stamp;
    const double last = first + static_cast<double>(*std::max_element(scan.time.begin(), scan.time.end()));
    if (first < kEarliestPeriods * period_ - kBoundSlackSeconds || last > kLatestPeriods * period_ + kBoundSlackSeconds) {
      const std::string field = "field " + std::string(find_time_field(*table)->name);
      throw InputError(gap.file, field,
                       "point times run from " + seconds_text(first) + " to " + seconds_text(last) + " s of frame " + std::to_string(k) +
                           "'s stamp " + seconds_text(frame_stamp) + " s; they must lie within [-1, 2] frame periods (" +
                           seconds_text(period_) + " s). Check the field's unit (the LiDAR's time_unit in dataset.yaml) and that " +
                           "the stamps and the clouds share one clock");
    }
  }
  if (std::string why = why_unusable(scan, lidar.model); !why.empty()) {
    gap.reason = ScanGap::kNoUsablePoint;
    gap.detail = std::move(why);
    return std::nullopt;
  }
  return scan;
}

std::optional<Scan> FrameSource::read_scan(std::size_t k, std::size_t j, SkippedScan* gap) const {
  SkippedScan why;
  std::optional<Scan> scan = load(k, j, why);
  if (gap != nullptr) *gap = std::move(why);
  return scan;
}

SourceFrame FrameSource::read(std::size_t k) const {
  SourceFrame frame;
  frame.index = k;
  frame.stamp = stamps_.at(k);
  for (std::size_t j = 0; j < lidars_.size(); ++j) {
    SkippedScan gap;
    frame.scans.push_back(load(k, j, gap));
    if (!frame.scans.back()) frame.skipped.push_back(std::move(gap));
  }
  return frame;
}

}  // namespace mlidar::io
