// `mlidar bag info BAG [--json]` and `mlidar bag export BAG --topics ... --out DATASET`: what a recording holds, and
// its LiDAR topics as a dataset folder exactly like the simulator's (io/bag_frames.hpp for the frame rule).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/mlidar/bag_options.hpp"
#include "apps/mlidar/commands.hpp"
#include "apps/mlidar/progress_bar.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/bag_reader.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/dataset.hpp"
#include "mlidar/io/run_folder.hpp"

namespace mlidar::cli {
namespace {

struct InfoOptions {
  std::string bag;
  bool json = false;
};

struct ExportOptions {
  BagCliOptions bag;
  std::string encoding = "binary";
  bool overwrite = false;
  std::string out;
};

/// A topic as `bag info` describes it.
struct TopicInfo {
  std::int64_t first_ns = 0, last_ns = 0;
  std::optional<io::PointCloud2> first_cloud;
};

nlohmann::json time_json(const io::PointCloud2& cloud) {
  const io::FieldColumn* field = io::find_time_field(cloud.table);
  if (field == nullptr) return nullptr;
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < cloud.table.num_points; ++i) {
    const double v = field->value(i);
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  nlohmann::json j{{"field", field->name}, {"type", io::scalar_name(field->type)}};
  try {
    const io::TimeUnit unit = io::time_unit_of(*field, io::TimeUnit::kAuto, "");
    const double scale = unit == io::TimeUnit::kNanoseconds    ? 1e-9
                         : unit == io::TimeUnit::kMicroseconds ? 1e-6
                         : unit == io::TimeUnit::kMilliseconds ? 1e-3
                                                               : 1.0;
    const bool absolute = std::abs(lo * scale) > 1e6;
    j["unit"] = io::time_unit_name(unit);
    j["reference"] = absolute ? "absolute" : "header stamp";
    j["stamp_at"] = absolute ? "any" : hi <= 0.0 ? "end" : lo >= 0.0 ? "start" : "within the sweep";
    j["span_s"] = std::isfinite(hi) ? (hi - lo) * scale : 0.0;
  } catch (const InputError& e) {
    j["unit"] = nullptr;
    j["problem"] = e.what();
  }
  return j;
}

nlohmann::json topic_json(const io::BagTopic& topic, const TopicInfo& info) {
  const double span = 1e-9 * static_cast<double>(info.last_ns - info.first_ns);
  nlohmann::json j{{"name", topic.name},
                   {"type", topic.type},
                   {"encoding", topic.encoding == io::MessageEncoding::kCdr ? "cdr" : "ros1"},
                   {"count", topic.count},
                   {"rate_hz", topic.count > 1 && span > 0.0 ? static_cast<double>(topic.count - 1) / span : 0.0}};
  if (!info.first_cloud) return j;
  const io::PointCloud2& cloud = *info.first_cloud;
  nlohmann::json fields = nlohmann::json::array();
  for (const auto& column : cloud.table.fields)
    fields.push_back({{"name", column.name}, {"type", io::scalar_name(column.type)}, {"count", column.count}});
  j["frame_id"] = cloud.header.frame_id;
  j["points"] = cloud.table.num_points;
  j["organized"] = cloud.height > 1;
  j["fields"] = fields;
  j["time"] = time_json(cloud);
  return j;
}

/// Every topic's span and first cloud: from the index when the bag has one that tells (no chunk decompressed but
/// the first of each topic: a bz2 bag of 650 MB took 33 s in a pass), else from a pass.
std::map<std::size_t, TopicInfo> topic_infos(io::BagReader& bag, std::int64_t& first, std::int64_t& last, std::uint64_t& messages) {
  std::map<std::size_t, TopicInfo> infos;
  const auto decode = [&](std::size_t t, std::span<const std::byte> data) {
    const io::BagTopic& topic = bag.topics()[t];
    if (topic.type.find("PointCloud2") != std::string::npos)
      infos[t].first_cloud = io::decode_pointcloud2(data, topic.encoding, bag.path().string() + ": topic " + topic.name + ", message 0");
  };
  if (auto indexed = bag.indexed_topics()) {
    for (std::size_t t = 0; t < indexed->size(); ++t) {
      const auto& i = (*indexed)[t];
      if (bag.topics()[t].count == 0) continue;
      infos[t].first_ns = i.first_ns, infos[t].last_ns = i.last_ns;
      first = std::min(first, i.first_ns), last = std::max(last, i.last_ns), messages += bag.topics()[t].count;
      decode(t, i.first_message);
    }
    return infos;
  }
  bag.for_each({}, [&](const io::BagMessage& m) {
    TopicInfo& info = infos[m.topic];
    if (m.index == 0) info.first_ns = m.log_time_ns;
    info.last_ns = m.log_time_ns;
    first = std::min(first, m.log_time_ns), last = std::max(last, m.log_time_ns), ++messages;
    if (m.index == 0) decode(m.topic, m.data);
  });
  return infos;
}

nlohmann::json bag_json(io::BagReader& bag) {
  std::int64_t first = INT64_MAX, last = INT64_MIN;
  std::uint64_t messages = 0;
  std::map<std::size_t, TopicInfo> infos = topic_infos(bag, first, last, messages);
  nlohmann::json topics = nlohmann::json::array();
  for (std::size_t t = 0; t < bag.topics().size(); ++t) topics.push_back(topic_json(bag.topics()[t], infos[t]));
  std::error_code ec;
  return {{"path", bag.path().string()},
          {"format", io::bag_format_name(bag.format())},
          {"size_bytes", std::filesystem::is_directory(bag.path()) ? 0 : std::filesystem::file_size(bag.path(), ec)},
          {"duration_s", messages > 1 ? 1e-9 * static_cast<double>(last - first) : 0.0},
          {"messages", messages},
          {"truncated", bag.truncated() ? nlohmann::json(*bag.truncated()) : nlohmann::json(nullptr)},
          {"topics", topics}};
}

void print_info(const nlohmann::json& j) {
  std::printf("%s\n  format    %s\n  duration  %.3f s, %llu messages\n", j["path"].get<std::string>().c_str(),
              j["format"].get<std::string>().c_str(), j["duration_s"].get<double>(),
              static_cast<unsigned long long>(j["messages"].get<std::uint64_t>()));
  if (!j["truncated"].is_null()) std::printf("  truncated %s\n", j["truncated"].get<std::string>().c_str());
  for (const auto& t : j["topics"]) {
    std::printf("  %-24s %-30s %6llu msgs %7.2f Hz", t["name"].get<std::string>().c_str(), t["type"].get<std::string>().c_str(),
                static_cast<unsigned long long>(t["count"].get<std::uint64_t>()), t["rate_hz"].get<double>());
    if (t.contains("points")) {
      std::printf("  frame %s, %zu points, fields", t["frame_id"].get<std::string>().c_str(), t["points"].get<std::size_t>());
      for (const auto& f : t["fields"]) std::printf(" %s:%s", f["name"].get<std::string>().c_str(), f["type"].get<std::string>().c_str());
      const auto& time = t["time"];
      if (time.is_null())
        std::printf("; no per-point time");
      else if (!time["unit"].is_null())
        std::printf("; time '%s' in %s, %s, stamp at %s", time["field"].get<std::string>().c_str(), time["unit"].get<std::string>().c_str(),
                    time["reference"].get<std::string>().c_str(), time["stamp_at"].get<std::string>().c_str());
      else
        std::printf("; time '%s': %s", time["field"].get<std::string>().c_str(), time["problem"].get<std::string>().c_str());
    }
    std::printf("\n");
  }
}

int run_info(const InfoOptions& options) {
  const auto bag = io::open_bag(options.bag);
  const nlohmann::json j = bag_json(*bag);
  if (options.json)
    std::cout << j.dump(2) << '\n';
  else
    print_info(j);
  return 0;
}

std::string frame_file(std::size_t k) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu.pcd", k);
  return name;
}

int run_export(const ExportOptions& options, const CliContext& context) {
  if (options.bag.topics.empty()) throw UsageError("bag export needs --topics TOPIC:LIDAR,... (mlidar bag info lists the topics)");
  io::RunFolder run(options.out, "bag export", context.run_folder(options.overwrite, {options.bag.bag}));
  const io::FrameSource source = io::FrameSource::bag(options.bag.bag, bag_source_options(options.bag));
  const io::Dataset& dataset = *source.dataset_info();
  for (const auto& lidar : dataset.lidars) std::filesystem::create_directories(run.path() / lidar.scans);
  const auto progress = terminal_progress_bar();
  for (std::size_t k = 0; k < source.frames(); ++k) {
    for (std::size_t j = 0; j < dataset.lidars.size(); ++j) {
      std::string name;
      std::optional<io::PointTable> table = source.read_table(k, j, name);
      if (!table) continue;
      io::CloudFile cloud;
      cloud.table = std::move(*table);
      io::write_cloud(run.path() / dataset.lidars[j].scans / frame_file(k), cloud, io::CloudWriteOptions{options.encoding});
    }
    if (progress) progress(static_cast<int>(k + 1), static_cast<int>(source.frames()));
  }
  io::write_times(run.path() / dataset.times, source.stamps());
  io::write_dataset_yaml(run.path() / "dataset.yaml", dataset);
  run.commit();
  std::cout << "wrote " << options.out << ": " << source.frames() << " frames of " << dataset.lidars.size() << " LiDAR(s), base "
            << dataset.base << ", frame period " << dataset.frame_period << " s\n";
  return 0;
}

}  // namespace

Command register_bag(CLI::App& app, const CliContext& context) {
  CLI::App* sub = app.add_subcommand("bag", "Read robots' recordings: ROS 1 bags, MCAP files and rosbag2 folders, without ROS");
  sub->require_subcommand(1);
  auto info = std::make_shared<InfoOptions>();
  CLI::App* info_cmd = sub->add_subcommand("info", "What a bag holds: storage, duration, topics, rates, point fields, time conventions");
  info_cmd->add_option("bag", info->bag, "A .bag, .mcap or .db3 file, or a rosbag2 folder")->required();
  info_cmd->add_flag("--json", info->json, "Print JSON");
  auto exp = std::make_shared<ExportOptions>();
  CLI::App* export_cmd = sub->add_subcommand("export", "A bag's LiDAR topics as a dataset folder (dataset.yaml, scans/NAME/, times.txt)");
  export_cmd->add_option("bag", exp->bag.bag, "A .bag, .mcap or .db3 file, or a rosbag2 folder")->required();
  add_bag_options(*export_cmd, exp->bag, false, true);
  export_cmd->add_option("--encoding", exp->encoding, "PCD encoding of the scans")
      ->check(CLI::IsMember({"binary", "binary_compressed"}))
      ->capture_default_str();
  export_cmd->add_option("--out", exp->out, "The dataset folder (a new or empty folder, or an earlier export)")->required();
  add_overwrite_flag(*export_cmd, exp->overwrite);
  return {sub, [info, exp, info_cmd, &context] { return info_cmd->parsed() ? run_info(*info) : run_export(*exp, context); }};
}

}  // namespace mlidar::cli
