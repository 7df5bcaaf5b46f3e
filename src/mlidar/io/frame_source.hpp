#pragma once
// io::FrameSource: the one way every job gets its frames. A source is a
// dataset folder (io/dataset.hpp: all or some of its LiDARs) or a folder of
// one LiDAR's clouds (every cloud a frame, in natural order, stamps k *
// period). It yields, per frame, the stamp and each LiDAR's Scan or none,
// parsing each cloud once.
//
// Which file is which frame: io/cloud_files.hpp (frame_clouds). A frame
// without a file has no scan (missing). Too few or too many stamps for the
// clouds is InputError naming times.txt and the folder. A bag is one more
// source (io/bag_frames.hpp): its messages give the clouds, under the same
// rules below.
//
// The per-point time rule (the only one): the time field is the first of t,
// time, timestamp, offset_time; its unit is the LiDAR's time_unit
// (dataset.yaml) or follows from its type (io::time_unit_of: float seconds,
// 32/64-bit integer nanoseconds). Values beyond 1e6 s are absolute (unix)
// times; smaller ones count from the frame stamp (they may be negative: a
// driver that stamps the sweep's end). In a Scan, `stamp` is the earliest
// point's time on the frames' clock and time[i] >= 0 counts from it. A folder
// of clouds has no clock (its stamps are k * period): there absolute times
// count from their earliest point, taken to be the frame stamp. Every point's
// time must lie within [-1, 2] frame periods of the frame stamp: anything else
// (a unit off by 1000, a wrong clock) is InputError naming the file and field.
//
// Unusable scans: a scan whose file holds no point, no finite point, or no
// point inside the model's [min_range, max_range] (and below its ring count,
// when both are known) is skipped: no scan at that frame, like a missing one,
// and reported in SourceFrame::skipped.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"
#include "mlidar/io/dataset.hpp"

namespace mlidar::io {

/// Why a LiDAR has no scan at a frame.
enum class ScanGap : std::uint8_t {
  kMissing,        ///< no file for this frame
  kEmpty,          ///< the file holds no point
  kNoFinitePoint,  ///< every point has a non-finite coordinate
  kNoUsablePoint,  ///< no point inside the model's range (or ring count)
};
/// "missing", "empty", "all_nan", "no_usable_point" (metrics.json's skipped_scans reasons).
const char* to_string(ScanGap gap);

struct SkippedScan {
  std::size_t frame = 0;
  std::size_t lidar = 0;  ///< index in FrameSource::lidars()
  ScanGap reason = ScanGap::kMissing;
  std::string file;    ///< the cloud, or empty when missing
  std::string detail;  ///< in words, e.g. "ring values 16-31 beyond the model's 16 rows"
};

struct SourceLidar {
  std::string name;
  LidarModel model;
  std::optional<SE3> initial_extrinsic;  ///< T_base_lidar from dataset.yaml
  TimeUnit time_unit = TimeUnit::kAuto;
  std::filesystem::path folder;  ///< where its clouds are
};

/// Where a source's clouds come from: files (folders) or a bag's messages (io/bag_frames.hpp).
class CloudProvider {
 public:
  virtual ~CloudProvider() = default;
  /// LiDAR j's cloud at frame k, or nullopt when it has none there; `name` is set to where it comes from (a
  /// file, or a bag's topic and message) for messages and reports.
  virtual std::optional<PointTable> cloud(std::size_t k, std::size_t j, std::string& name) const = 0;
};

/// How a bag's topics become frames (io/bag_frames.hpp).
struct BagSourceOptions;

struct SourceFrame {
  std::size_t index = 0;
  double stamp = 0.0;
  std::vector<std::optional<Scan>> scans;  ///< per LiDAR, lidars() order; nullopt: missing or skipped
  std::vector<SkippedScan> skipped;        ///< this frame's gaps, missing ones included
};

class FrameSource {
 public:
  /// A dataset folder; `lidars` selects some of its LiDARs by name (empty:
  /// all), in dataset order. UsageError for a name it does not have.
  static FrameSource dataset(const std::filesystem::path& folder, std::span<const std::string> lidars = {});
  /// A folder of one LiDAR's clouds, `period` seconds apart (> 0), or at the
  /// stamps of `times` (one per cloud in the clouds' natural order, strictly
  /// increasing, as times.txt; its median gap is then the period). InputError
  /// naming `times` when its count differs from the clouds'.
  /// `model`: the clouds' LiDAR (e.g. from `--model OS1-64`); empty (no rings): the front end recovers rows or uses voxels.
  static FrameSource scan_folder(const std::filesystem::path& folder, double period,
                                 const std::optional<std::filesystem::path>& times = std::nullopt, const LidarModel& model = {});
  /// A bag's PointCloud2 topics (io/bag_frames.hpp: the frames follow the base LiDAR's scans).
  static FrameSource bag(const std::filesystem::path& path, const BagSourceOptions& options);

  const std::vector<SourceLidar>& lidars() const { return lidars_; }
  const std::vector<double>& stamps() const { return stamps_; }
  std::size_t frames() const { return stamps_.size(); }
  /// Seconds between frames (dataset.yaml's frame_period, or the folder's period).
  double period() const { return period_; }
  /// The dataset (its base, ground truth, ...); nullopt for a folder of clouds. A bag's is built from its topics.
  const std::optional<Dataset>& dataset_info() const { return dataset_; }
  /// Index in lidars() of the LiDAR that defines the base frame: the base LiDAR, or the dataset's reference_lidar
  /// when the base frame is no LiDAR (the folder's one LiDAR); nullopt when it is not selected.
  std::optional<std::size_t> reference_index() const;
  /// Index in lidars() of the LiDAR called `name`, or nullopt.
  std::optional<std::size_t> find(const std::string& name) const;

  /// What the reader noticed about its input, in words (a bag cut short, scans no frame took); empty for folders.
  const std::vector<std::string>& notes() const { return notes_; }

  /// Frame k (< frames()): each LiDAR's cloud parsed once.
  SourceFrame read(std::size_t k) const;
  /// LiDAR j's scan at frame k alone; when none, `gap` (if given) says why.
  std::optional<Scan> read_scan(std::size_t k, std::size_t j, SkippedScan* gap = nullptr) const;
  /// LiDAR j's cloud at frame k as it comes (every field; a bag's times as `t` from the frame stamp), or nullopt;
  /// `name` is set to where it comes from. What `mlidar bag export` writes.
  std::optional<PointTable> read_table(std::size_t k, std::size_t j, std::string& name) const { return clouds_->cloud(k, j, name); }

 private:
  FrameSource() = default;
  std::optional<Scan> load(std::size_t k, std::size_t j, SkippedScan& gap) const;

  std::vector<SourceLidar> lidars_;
  std::vector<double> stamps_;
  double period_ = 0.1;
  bool own_clock_ = true;  ///< the stamps come from times.txt (absolute point times are compared with them)
  std::optional<Dataset> dataset_;
  std::shared_ptr<const CloudProvider> clouds_;
  std::vector<std::string> notes_;
};

}  // namespace mlidar::io
