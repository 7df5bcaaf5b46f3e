#include "mlidar/pipelines/frame_gaps.hpp"

#include <cstdio>
#include <map>

#include "mlidar/core/error.hpp"

namespace mlidar::pipelines {
namespace {

/// "4, 9 and 17", the first few and a count of the rest.
std::string frame_list(const std::vector<std::size_t>& frames) {
  constexpr std::size_t kShown = 5;
  std::string text;
  for (std::size_t i = 0; i < frames.size() && i < kShown; ++i) {
    if (i > 0) text += (i + 1 == frames.size() ? " and " : ", ");
    text += std::to_string(frames[i]);
  }
  if (frames.size() > kShown) text += " and " + std::to_string(frames.size() - kShown) + " more";
  return text;
}

}  // namespace

io::FrameSource open_frames(const std::filesystem::path& dataset, const std::filesystem::path& bag,
                            const io::BagSourceOptions& bag_options) {
  if (dataset.empty() == bag.empty()) throw UsageError("give exactly one of --dataset DIR or --bag BAG");
  if (bag.empty()) return io::FrameSource::dataset(dataset);
  if (bag_options.topics.empty()) throw UsageError("--bag needs --topics TOPIC:LIDAR,... (mlidar bag info lists the topics)");
  return io::FrameSource::bag(bag, bag_options);
}

nlohmann::json FrameGaps::json() const {
  nlohmann::json out = nlohmann::json::array();
  for (const io::SkippedScan& gap : gaps_) {
    out.push_back({{"frame", gap.frame},
                   {"lidar", source_->lidars()[gap.lidar].name},
                   {"reason", io::to_string(gap.reason)},
                   {"file", gap.file.empty() ? nlohmann::json(nullptr) : nlohmann::json(gap.file)},
                   {"detail", gap.detail}});
  }
  return out;
}

std::vector<std::string> FrameGaps::summary_lines() const {
  std::vector<std::string> lines = source_->notes();
  for (std::size_t j = 0; j < source_->lidars().size(); ++j) {
    std::vector<std::size_t> frames;
    std::map<std::string, std::size_t> reasons;
    std::string detail;
    for (const io::SkippedScan& gap : gaps_) {
      if (gap.lidar != j) continue;
      frames.push_back(gap.frame);
      ++reasons[io::to_string(gap.reason)];
      if (detail.empty()) detail = gap.detail;
    }
    if (frames.empty()) continue;
    std::string counts;
    for (const auto& [reason, count] : reasons) counts += (counts.empty() ? "" : ", ") + std::to_string(count) + " " + reason;
    std::string line = source_->lidars()[j].name + ": " + std::to_string(frames.size()) + " of " + std::to_string(source_->frames()) +
                       " frames without a usable scan (frame" + (frames.size() > 1 ? "s " : " ") + frame_list(frames) + ": " + counts + ")";
    if (!detail.empty()) line += "; e.g. " + detail;
    lines.push_back(std::move(line));
  }
  return lines;
}

std::optional<std::string> FrameGaps::base_failure(double max_share, std::optional<std::size_t> base) const {
  if (!base || source_->frames() == 0) return std::nullopt;
  std::size_t missing = 0;
  for (const io::SkippedScan& gap : gaps_) missing += gap.lidar == *base ? 1 : 0;
  const double share = static_cast<double>(missing) / static_cast<double>(source_->frames());
  if (share <= max_share) return std::nullopt;
  char text[64];
  std::snprintf(text, sizeof text, "%.0f %% (limit %.0f %%, --max-base-gaps)", 100.0 * share, 100.0 * max_share);
  return "the base LiDAR " + source_->lidars()[*base].name + " has no usable scan in " + std::to_string(missing) + " of " +
         std::to_string(source_->frames()) + " frames: " + text + "; the trajectory is not trustworthy (see metrics.json skipped_scans)";
}

}  // namespace mlidar::pipelines
