#pragma once
// A bag as a frame source (FrameSource::bag). Frames follow the base LiDAR:
// each of its scans is a frame, stamped at the scan's earliest point. Every
// other LiDAR's scan goes to the frame whose base sweep it overlaps most
// (ties: the earlier frame); a second scan for the same frame keeps the larger
// overlap and the other is reported as dropped, like a scan overlapping no
// frame. The per-point times are kept, as seconds relative to the frame stamp
// in a field `t` (float64), so the deskew brings every point to one time.
//
// Per-point time conventions: the field t, time, timestamp or offset_time (the
// first present), float = seconds, 32/64-bit integer = nanoseconds (Velodyne
// `time` float32 relative to the header stamp, may be negative; Ouster `t`
// uint32 ns; Hesai and RoboSense `timestamp` float64 absolute; Livox
// `offset_time` uint32 ns). Values above 1e6 s are absolute. Relative values
// count from the header stamp (--stamp-at auto or start), or, with --stamp-at
// end and offsets that are never negative, from the sweep start one span
// before the header stamp. Without a time field the sweep lasts one period
// from the header stamp (start, auto) or up to it (end).
//
// Extrinsics: --extrinsics FILE, else /tf_static (the tf tree between the
// LiDARs' frame_ids), else none. LiDAR models: from a dataset.yaml naming the
// LiDARs (--models), else unknown (no vertical angles).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mlidar/io/bag_reader.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/frame_source.hpp"

namespace mlidar::io {

struct BagLidarTopic {
  std::string topic;  ///< e.g. /top/points
  std::string lidar;  ///< its LiDAR's name, e.g. top
};

enum class StampAt { kAuto, kStart, kEnd };

struct BagSourceOptions {
  std::vector<BagLidarTopic> topics;  ///< the LiDARs, in this order
  std::string base;                   ///< the base LiDAR's name (empty: the first)
  StampAt stamp_at = StampAt::kAuto;
  double start_s = 0.0;                  ///< frames from this many seconds after the first base sweep
  std::optional<double> duration_s;      ///< ... lasting this long (nullopt: to the end)
  std::optional<Extrinsics> extrinsics;  ///< instead of /tf_static
  std::optional<Dataset> models;         ///< LiDAR models by name
};

/// A bag's options as the command line (and the Python module) write them: names and files, not yet read.
struct BagArguments {
  std::string bag;
  std::string topics;             ///< /a:top,/b:front
  std::string base;               ///< the base LiDAR (default: the first of topics)
  std::string stamp_at = "auto";  ///< auto, start or end (anything else: UsageError)
  std::string extrinsics;         ///< YAML; default /tf_static
  std::string models;             ///< a dataset.yaml naming the LiDARs' models
  double start_s = 0.0;
  double duration_s = 0.0;  ///< 0: to the end
};

/// The frame source's options, the files they name read (InputError naming a bad one).
BagSourceOptions bag_source_options(const BagArguments& arguments);

/// "/a:top,/b:front" -> topics; UsageError naming --topics otherwise.
std::vector<BagLidarTopic> parse_bag_topics(const std::string& text);

/// The T_base_lidar of every LiDAR whose frame_id the transforms connect to the base's, from a tf tree.
std::vector<std::optional<SE3>> extrinsics_from_tf(const std::vector<RosTransform>& transforms, const std::vector<std::string>& frame_ids,
                                                   std::size_t base);

}  // namespace mlidar::io
