#include "mlidar/io/bag_frames.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "mlidar/core/error.hpp"
#include "mlidar/core/median.hpp"

namespace mlidar::io {
namespace {

/// A topic's per-point time field and how to read it.
struct TimeField {
  std::string name;  ///< empty: none
  double scale = 1.0;
  bool absolute = false;
};

/// One message of a LiDAR topic: where it is and the span of its sweep (absolute seconds).
struct Sweep {
  MessageRef where;
  std::uint64_t index = 0;
  double header_stamp = 0.0;
  double start = 0.0, end = 0.0;
};

struct LidarTopic {
  std::size_t topic = 0;
  std::string name;                      ///< the topic's
  TimeUnit time_unit = TimeUnit::kAuto;  ///< of its time field (--models' time_unit), kAuto: from the type
  MessageEncoding encoding = MessageEncoding::kRos1;
  std::optional<TimeField> time;  ///< set by the first message
  std::string frame_id;
  std::vector<Sweep> sweeps;
};

std::string message_source(const BagReader& bag, const std::string& topic, std::uint64_t index) {
  return bag.path().string() + ": topic " + topic + ", message " + std::to_string(index);
}

TimeField time_field_of(const PointCloud2& cloud, TimeUnit requested, const std::string& source) {
  TimeField field;
  const FieldColumn* column = find_time_field(cloud.table);
  if (column == nullptr) return field;
  field.name = column->name;
  const TimeUnit unit =
      time_unit_of(*column, requested, source + " (give its unit as the LiDAR's time_unit in a dataset.yaml passed with --models)");
  field.scale = unit == TimeUnit::kNanoseconds    ? 1e-9
                : unit == TimeUnit::kMicroseconds ? 1e-6
                : unit == TimeUnit::kMilliseconds ? 1e-3
                                                  : 1.0;
  for (std::size_t i = 0; i < cloud.table.num_points; ++i) {
    const double v = column->value(i);
    if (std::isfinite(v)) {
      field.absolute = std::abs(v * field.scale) > 1e6;
      break;
    }
  }
  return field;
}

/// The absolute times of a cloud's points (seconds), by its topic's convention.
std::vector<double> point_times(const PointCloud2& cloud, const TimeField& field, StampAt stamp_at) {
  const FieldColumn* column = cloud.table.find(field.name);
  std::vector<double> times(cloud.table.num_points);
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < times.size(); ++i) {
    times[i] = column->value(i) * field.scale;
    if (std::isfinite(times[i])) lo = std::min(lo, times[i]), hi = std::max(hi, times[i]);
  }
  if (field.absolute) return times;
  const double origin = cloud.header.stamp.seconds() - (stamp_at == StampAt::kEnd && lo >= 0.0 && std::isfinite(hi) ? hi : 0.0);
  for (double& t : times) t += origin;
  return times;
}

/// Clouds of the frames from the bag's messages, each with its times as `t` seconds from its frame stamp.
class BagClouds final : public CloudProvider {
 public:
  BagClouds(std::shared_ptr<BagReader> bag, std::vector<LidarTopic> lidars, std::vector<std::vector<std::optional<std::size_t>>> assigned,
            std::vector<double> stamps, StampAt stamp_at)
      : bag_(std::move(bag)), lidars_(std::move(lidars)), assigned_(std::move(assigned)), stamps_(std::move(stamps)), stamp_at_(stamp_at) {}

  std::optional<PointTable> cloud(std::size_t k, std::size_t j, std::string& name) const override {
    const std::optional<std::size_t> s = assigned_[j][k];
    if (!s) return std::nullopt;
    const LidarTopic& lidar = lidars_[j];
    const Sweep& sweep = lidar.sweeps[*s];
    name = message_source(*bag_, lidar.name, sweep.index);
    const std::vector<std::byte> data = bag_->read(sweep.where);
    PointCloud2 cloud = decode_pointcloud2(data, lidar.encoding, name);
    if (!lidar.time || lidar.time->name.empty()) return std::move(cloud.table);
    const std::vector<double> times = point_times(cloud, *lidar.time, stamp_at_);
    PointTable table;
    table.num_points = cloud.table.num_points;
    table.width = cloud.table.width;
    table.height = cloud.table.height;
    for (auto& column : cloud.table.fields)
      if (column.name != lidar.time->name && column.name != "t") table.fields.push_back(std::move(column));
    FieldColumn& t = table.add_field("t", ScalarType::kF64);
    for (std::size_t i = 0; i < times.size(); ++i) {
      const double relative = times[i] - stamps_[k];
      std::memcpy(t.data.data() + 8 * i, &relative, 8);
    }
    return table;
  }

 private:
  std::shared_ptr<BagReader> bag_;
  std::vector<LidarTopic> lidars_;
  std::vector<std::vector<std::optional<std::size_t>>> assigned_;  ///< [lidar][frame] -> sweep
  std::vector<double> stamps_;
  StampAt stamp_at_;
};

double median_interval(const std::vector<Sweep>& sweeps) {
  std::vector<double> gaps;
  for (std::size_t i = 1; i < sweeps.size(); ++i) gaps.push_back(sweeps[i].header_stamp - sweeps[i - 1].header_stamp);
  if (gaps.empty()) return 0.1;
  const double median = upper_median(std::move(gaps));
  return median > 0.0 ? median : 0.1;
}

/// Index pass: every LiDAR topic's sweeps (and /tf_static's transforms).
std::vector<RosTransform> index_sweeps(BagReader& bag, std::vector<LidarTopic>& lidars, std::optional<std::size_t> tf_static,
                                       StampAt stamp_at) {
  std::vector<bool> wanted(bag.topics().size(), false);
  std::map<std::size_t, std::size_t> lidar_of;
  for (std::size_t j = 0; j < lidars.size(); ++j) wanted[lidars[j].topic] = true, lidar_of[lidars[j].topic] = j;
  if (tf_static) wanted[*tf_static] = true;
  std::vector<RosTransform> transforms;
  bag.for_each(wanted, [&](const BagMessage& m) {
    const std::string name = message_source(bag, bag.topics()[m.topic].name, m.index);
    if (tf_static && m.topic == *tf_static) {
      const auto more = decode_tf_message(m.data, bag.topics()[m.topic].encoding, name);
      transforms.insert(transforms.end(), more.begin(), more.end());
      return;
    }
    LidarTopic& lidar = lidars[lidar_of.at(m.topic)];
    const std::vector<std::string> time_fields(std::begin(kTimeFieldNames), std::end(kTimeFieldNames));
    const PointCloud2 cloud = decode_pointcloud2(m.data, lidar.encoding, name, &time_fields);
    if (!lidar.time) lidar.time = time_field_of(cloud, lidar.time_unit, name), lidar.frame_id = cloud.header.frame_id;
    Sweep sweep{m.where, m.index, cloud.header.stamp.seconds(), NAN, NAN};
    if (!lidar.time->name.empty()) {
      for (const double t : point_times(cloud, *lidar.time, stamp_at))
        if (std::isfinite(t))
          sweep.start = std::isnan(sweep.start) ? t : std::min(sweep.start, t),
          sweep.end = std::isnan(sweep.end) ? t : std::max(sweep.end, t);
    }
    lidar.sweeps.push_back(sweep);
  });
  for (LidarTopic& lidar : lidars) {  // sweeps without times: one period from (or up to) the header stamp
    const double period = median_interval(lidar.sweeps);
    for (Sweep& s : lidar.sweeps) {
      if (!std::isnan(s.start)) continue;
      s.start = stamp_at == StampAt::kEnd ? s.header_stamp - period : s.header_stamp;
      s.end = s.start + period;
    }
    std::stable_sort(lidar.sweeps.begin(), lidar.sweeps.end(), [](const Sweep& a, const Sweep& b) { return a.start < b.start; });
  }
  return transforms;
}

double overlap(const Sweep& a, double start, double end) { return std::max(0.0, std::min(a.end, end) - std::max(a.start, start)); }

/// The base sweeps inside the window: their indices in the base's sweeps.
std::vector<std::size_t> frame_sweeps(const LidarTopic& base, const BagSourceOptions& options) {
  std::vector<std::size_t> frames;
  const double first = base.sweeps.front().start + options.start_s;
  for (std::size_t i = 0; i < base.sweeps.size(); ++i) {
    const double start = base.sweeps[i].start;
    if (start + 1e-9 < first) continue;
    if (options.duration_s && start >= first + *options.duration_s) break;
    frames.push_back(i);
  }
  return frames;
}

/// [lidar][frame] -> the sweep of that LiDAR overlapping the frame's base sweep most (each sweep in one frame).
std::vector<std::vector<std::optional<std::size_t>>> assign(const std::vector<LidarTopic>& lidars, std::size_t base,
                                                            const std::vector<std::size_t>& frames) {
  const LidarTopic& b = lidars[base];
  std::vector<std::vector<std::optional<std::size_t>>> assigned(lidars.size(), std::vector<std::optional<std::size_t>>(frames.size()));
  for (std::size_t k = 0; k < frames.size(); ++k) assigned[base][k] = frames[k];
  for (std::size_t j = 0; j < lidars.size(); ++j) {
    if (j == base) continue;
    std::vector<double> best(frames.size(), 0.0);
    for (std::size_t s = 0; s < lidars[j].sweeps.size(); ++s) {
      const Sweep& sweep = lidars[j].sweeps[s];
      std::optional<std::size_t> frame;
      double most = 0.0;
      for (std::size_t k = 0; k < frames.size(); ++k) {  // frames are few where the sweep can overlap: stop past it
        const Sweep& f = b.sweeps[frames[k]];
        if (f.start > sweep.end) break;
        const double o = overlap(sweep, f.start, f.end);
        if (o > most) most = o, frame = k;
      }
      if (frame && most > best[*frame]) best[*frame] = most, assigned[j][*frame] = s;
    }
  }
  return assigned;
}

Dataset bag_dataset(const std::filesystem::path& path, const BagSourceOptions& options, const std::vector<LidarTopic>& lidars,
                    std::size_t base, const std::vector<std::optional<SE3>>& extrinsics, double period) {
  Dataset dataset;
  dataset.name = path.stem().string();
  dataset.frame_period = period;
  dataset.base = options.topics[base].lidar;
  for (std::size_t j = 0; j < lidars.size(); ++j) {
    DatasetLidar lidar;
    lidar.name = options.topics[j].lidar;
    lidar.model.name = "unknown";
    if (options.models) {
      const auto it =
          std::find_if(options.models->lidars.begin(), options.models->lidars.end(), [&](const auto& l) { return l.name == lidar.name; });
      if (it != options.models->lidars.end()) lidar.model = it->model, lidar.time_unit = it->time_unit;
    }
    lidar.scans = std::filesystem::path("scans") / lidar.name;
    lidar.initial_extrinsic = j == base ? std::optional(SE3::identity()) : extrinsics[j];
    dataset.lidars.push_back(std::move(lidar));
  }
  return dataset;
}

/// Each LiDAR's T_base_lidar: from --extrinsics (whatever base that file uses), else the tf tree.
std::vector<std::optional<SE3>> lidar_extrinsics(const BagSourceOptions& options, const std::vector<LidarTopic>& lidars, std::size_t base,
                                                 const std::vector<RosTransform>& transforms) {
  if (!options.extrinsics) {
    std::vector<std::string> frame_ids;
    for (const LidarTopic& l : lidars) frame_ids.push_back(l.frame_id);
    return extrinsics_from_tf(transforms, frame_ids, base);
  }
  const Extrinsics& given = *options.extrinsics;
  const LidarExtrinsic* base_entry = given.find(options.topics[base].lidar);
  std::vector<std::optional<SE3>> out;
  for (const BagLidarTopic& t : options.topics) {
    const LidarExtrinsic* entry = given.find(t.lidar);
    if (entry == nullptr)
      out.emplace_back();
    else if (given.base == options.topics[base].lidar || base_entry == nullptr)
      out.push_back(entry->T_base_lidar);
    else
      out.push_back(base_entry->T_base_lidar.inverse() * entry->T_base_lidar);
  }
  return out;
}

}  // namespace

std::vector<BagLidarTopic> parse_bag_topics(const std::string& text) {
  std::vector<BagLidarTopic> topics;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');) {
    const auto colon = item.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == item.size())
      throw UsageError("--topics '" + text + "': expected TOPIC:LIDAR pairs separated by commas, e.g. /top/points:top,/front/points:front");
    topics.push_back({item.substr(0, colon), item.substr(colon + 1)});
  }
  if (topics.empty()) throw UsageError("--topics: name at least one TOPIC:LIDAR pair");
  return topics;
}

std::vector<std::optional<SE3>> extrinsics_from_tf(const std::vector<RosTransform>& transforms, const std::vector<std::string>& frame_ids,
                                                   std::size_t base) {
  std::map<std::string, std::pair<std::string, SE3>> parent;  // child -> (parent, T_parent_child)
  for (const RosTransform& t : transforms) parent[t.child_frame_id] = {t.header.frame_id, t.T_parent_child};
  const auto to_root = [&](std::string frame) {  // (root, T_root_frame)
    SE3 T;
    for (std::size_t depth = 0; parent.count(frame) && depth < 64; ++depth) {
      T = parent[frame].second * T;
      frame = parent[frame].first;
    }
    return std::pair{frame, T};
  };
  const auto [base_root, T_root_base] = to_root(frame_ids[base]);
  std::vector<std::optional<SE3>> out;
  for (const std::string& id : frame_ids) {
    const auto [root, T_root_lidar] = to_root(id);
    if (root == base_root)
      out.push_back(T_root_base.inverse() * T_root_lidar);
    else
      out.emplace_back();
  }
  return out;
}

FrameSource FrameSource::bag(const std::filesystem::path& path, const BagSourceOptions& options) {
  std::shared_ptr<BagReader> bag = open_bag(path);
  std::vector<LidarTopic> topics;
  for (const BagLidarTopic& t : options.topics) {
    const std::optional<std::size_t> topic = bag->find_topic(t.topic);
    if (!topic) throw InputError(path.string(), "topic " + t.topic, "not in the bag (mlidar bag info lists its topics)");
    const std::string& type = bag->topics()[*topic].type;
    if (type.find("PointCloud2") == std::string::npos)
      throw InputError(path.string(), "topic " + t.topic, "is " + type + ", not sensor_msgs/PointCloud2");
    TimeUnit unit = TimeUnit::kAuto;
    if (options.models)
      for (const DatasetLidar& l : options.models->lidars)
        if (l.name == t.lidar) unit = l.time_unit;
    topics.push_back({*topic, t.topic, unit, bag->topics()[*topic].encoding, std::nullopt, {}, {}});
  }
  std::size_t base = 0;
  if (!options.base.empty()) {
    const auto it = std::find_if(options.topics.begin(), options.topics.end(), [&](const auto& t) { return t.lidar == options.base; });
    if (it == options.topics.end()) throw UsageError("--base: no LiDAR '" + options.base + "' among --topics");
    base = static_cast<std::size_t>(it - options.topics.begin());
  }
  const std::vector<RosTransform> transforms =
      index_sweeps(*bag, topics, options.extrinsics ? std::nullopt : bag->find_topic("/tf_static"), options.stamp_at);
  if (topics[base].sweeps.empty())
    throw InputError(path.string(), "topic " + topics[base].name, "holds no message (the base LiDAR defines the frames)");
  const std::vector<std::size_t> frames = frame_sweeps(topics[base], options);
  if (frames.empty()) throw UsageError("--start / --duration select no frame of the bag");
  FrameSource source;
  source.period_ = std::round(median_interval(topics[base].sweeps) * 1e6) / 1e6;  // to the microsecond: stamps near 1.7e9 s hold 0.24 us
  source.own_clock_ = true;
  for (const std::size_t i : frames) source.stamps_.push_back(topics[base].sweeps[i].start);
  source.dataset_ = bag_dataset(path, options, topics, base, lidar_extrinsics(options, topics, base, transforms), source.period_);
  for (const DatasetLidar& l : source.dataset_->lidars) source.lidars_.push_back({l.name, l.model, l.initial_extrinsic, l.time_unit, path});
  std::vector<std::vector<std::optional<std::size_t>>> assigned = assign(topics, base, frames);
  if (bag->truncated()) source.notes_.push_back(path.string() + ": " + *bag->truncated());
  for (std::size_t j = 0; j < topics.size(); ++j) {
    const std::size_t used =
        static_cast<std::size_t>(std::count_if(assigned[j].begin(), assigned[j].end(), [](const auto& s) { return s.has_value(); }));
    const std::size_t dropped = topics[j].sweeps.size() - used;
    if (j != base && dropped > 0)
      source.notes_.push_back(options.topics[j].lidar + ": " + std::to_string(dropped) + " of " + std::to_string(topics[j].sweeps.size()) +
                              " scans in no frame (overlapping no base sweep of the frames read, or a frame's second scan)");
  }
  source.clouds_ = std::make_shared<BagClouds>(std::move(bag), std::move(topics), std::move(assigned), source.stamps_, options.stamp_at);
  return source;
}

BagSourceOptions bag_source_options(const BagArguments& arguments) {
  BagSourceOptions out;
  if (!arguments.topics.empty()) out.topics = parse_bag_topics(arguments.topics);
  out.base = arguments.base;
  if (arguments.stamp_at != "auto" && arguments.stamp_at != "start" && arguments.stamp_at != "end")
    throw UsageError("--stamp-at is '" + arguments.stamp_at + "': use auto, start or end");
  out.stamp_at = arguments.stamp_at == "start" ? StampAt::kStart : arguments.stamp_at == "end" ? StampAt::kEnd : StampAt::kAuto;
  out.start_s = arguments.start_s;
  if (arguments.duration_s > 0.0) out.duration_s = arguments.duration_s;
  if (!arguments.extrinsics.empty()) out.extrinsics = read_extrinsics(arguments.extrinsics);
  if (!arguments.models.empty()) out.models = read_dataset_yaml(arguments.models);
  return out;
}

}  // namespace mlidar::io
