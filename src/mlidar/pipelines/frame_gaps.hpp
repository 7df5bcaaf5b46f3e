#pragma once
// Opening a job's frames, and the scans its frame source could not give (missing files, empty, all-NaN
// or unusable scans): collected over the run, written to metrics.json as
// skipped_scans, summarized on the terminal, and the rule that fails a job
// whose base LiDAR lacks too many frames.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mlidar/io/bag_frames.hpp"
#include "mlidar/io/frame_source.hpp"

namespace mlidar::pipelines {

/// A job's frames: a dataset folder or a bag (exactly one of them; UsageError otherwise).
io::FrameSource open_frames(const std::filesystem::path& dataset, const std::filesystem::path& bag,
                            const io::BagSourceOptions& bag_options);

/// The default largest share of frames the base LiDAR may lack a usable scan in (--max-base-gaps).
inline constexpr double kDefaultMaxBaseGaps = 0.2;

class FrameGaps {
 public:
  explicit FrameGaps(const io::FrameSource& source) : source_(&source) {}

  void add(const std::vector<io::SkippedScan>& skipped) { gaps_.insert(gaps_.end(), skipped.begin(), skipped.end()); }
  const std::vector<io::SkippedScan>& all() const { return gaps_; }

  /// [{frame, lidar, reason, file (null when missing), detail}], frame order.
  nlohmann::json json() const;
  /// The source's notes (a bag cut short), then one line per LiDAR with gaps: "top: 3 of 100 frames without a usable
  /// scan (frames 4, 9 and 17: 2 empty, 1 missing)".
  std::vector<std::string> summary_lines() const;
  /// Why the job must fail: the base LiDAR (index in the source's lidars(); nullopt: none selected) lacks a usable scan
  /// in more than `max_share` of the frames; nullopt when not.
  std::optional<std::string> base_failure(double max_share, std::optional<std::size_t> base) const;

 private:
  const io::FrameSource* source_;
  std::vector<io::SkippedScan> gaps_;
};

}  // namespace mlidar::pipelines
