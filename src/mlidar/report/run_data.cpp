// Reading a run folder for its report (run_report.hpp).
#include <system_error>

#include "mlidar/core/error.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/point_covariance_fields.hpp"
#include "mlidar/io/point_table.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/report/run_report.hpp"

namespace mlidar::report {
namespace {

namespace fs = std::filesystem;

bool is_file(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

nlohmann::json read_json(const fs::path& path) {
  const std::string text = io::read_file_text(path);
  nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded()) throw InputError(path.string(), "", "not valid JSON; run the job again to rewrite it");
  return json;
}

/// The value after `--dataset` in run.json's arguments, or empty.
std::string dataset_argument(const nlohmann::json& run_info) {
  if (!run_info.is_object() || !run_info.contains("arguments") || !run_info["arguments"].is_array()) return {};
  const nlohmann::json& arguments = run_info["arguments"];
  for (std::size_t i = 0; i + 1 < arguments.size(); ++i)
    if (arguments[i] == "--dataset" && arguments[i + 1].is_string()) return arguments[i + 1].get<std::string>();
  return {};
}

/// Reads an optional file of the run; a file that is there but cannot be read becomes a note, not an abort.
template <typename T, typename Read>
std::optional<T> read_optional(const fs::path& path, Read read, std::vector<std::string>& notes) {
  if (!is_file(path)) return std::nullopt;
  try {
    return read(path);
  } catch (const std::exception& error) {
    notes.push_back(path.string() + " could not be read: " + error.what());
    return std::nullopt;
  }
}

struct MapPoints {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> traces;         ///< one per point, or empty
  std::vector<std::uint8_t> lidars;  ///< one per point, or empty
};

/// map.ply's points and, when it has them, their covariances' traces (a map with covariances has only finite points).
MapPoints read_map(const fs::path& path) {
  const io::CloudFile cloud = io::read_cloud(path);
  MapPoints map{io::to_scan(cloud.table, path.string()).points, {}, {}};
  if (const auto covariances = io::read_point_covariances(cloud.table, path.string());
      covariances && covariances->size() == map.points.size())
    for (const io::UpperCovariance& c : *covariances) map.traces.push_back(c[0] + c[3] + c[5]);
  // The LiDAR of each point, kept only when every point has a position (to_scan keeps the finite ones).
  if (const io::FieldColumn* lidar = cloud.table.find("lidar");
      lidar != nullptr && lidar->type == io::ScalarType::kU8 && cloud.table.num_points == map.points.size())
    for (std::size_t i = 0; i < cloud.table.num_points; ++i) map.lidars.push_back(static_cast<std::uint8_t>(lidar->value(i)));
  return map;
}

/// The last name of `path`, also for "run/" and "./run".
std::string folder_name(const fs::path& path) {
  fs::path normal = path.lexically_normal();
  if (normal.filename().empty()) normal = normal.parent_path();
  return normal.filename().string();
}

}  // namespace

RunData load_run(const fs::path& folder, const ReportSource& source) {
  const std::string& command = source.command;
  std::error_code error;
  if (!fs::is_directory(folder, error)) throw InputError(folder.string(), "", "not a folder; give a run folder written by an mlidar job");
  RunData run;
  run.folder = folder;
  run.title_folder = folder_name(source.shown_folder.empty() ? folder : source.shown_folder);
  if (is_file(folder / "run.json")) run.run_info = read_json(folder / "run.json");
  if (!run.run_info.is_null() && !run.run_info.is_object())
    throw InputError((folder / "run.json").string(), "", "not a JSON object; run the job again to rewrite it");
  run.command = !command.empty() || run.run_info.is_null() ? command : run.run_info.value("command", std::string{});
  if (run.run_info.is_null() && command.empty())
    throw InputError((folder / "run.json").string(), "", "missing: this is not an mlidar run folder (give the --out of a job)");
  for (const char* name : {"metrics.json", "calibration.json", "eval.json"})  // slam/odometry, calibrate auto, eval traj
    if (is_file(folder / name)) {
      run.metrics = read_json(folder / name);
      break;
    }
  run.trajectory = read_optional<Trajectory>(
      folder / "trajectory.tum", [](const fs::path& p) { return io::read_tum(p); }, run.notes);
  if (auto covariances = read_optional<std::vector<io::StampedCovariance>>(
          folder / "pose_covariance.txt", [](const fs::path& p) { return io::read_pose_covariances(p); }, run.notes))
    run.pose_covariances = std::move(*covariances);
  run.extrinsics = read_optional<io::Extrinsics>(
      folder / "extrinsics.yaml", [](const fs::path& p) { return io::read_extrinsics(p); }, run.notes);
  if (auto map = read_optional<MapPoints>(folder / "map.ply", read_map, run.notes)) {
    run.map = std::move(map->points);
    run.map_traces = std::move(map->traces);
    run.map_lidars = std::move(map->lidars);
  }
  run.dataset = !source.dataset.empty() ? source.dataset.string() : dataset_argument(run.run_info);
  if (is_file(folder / "groundtruth.tum")) {  // eval traj: the ground truth it was given, associated
    run.gt_trajectory = read_optional<Trajectory>(
        folder / "groundtruth.tum", [](const fs::path& p) { return io::read_tum(p); }, run.notes);
    return run;
  }
  if (run.dataset.empty()) return run;
  const fs::path truth = fs::path(run.dataset) / "groundtruth";
  if (!fs::is_directory(truth, error)) {
    run.notes.push_back("no ground truth: " + truth.string() + " is not there (rebuild with `mlidar report RUN --dataset DATASET`)");
    return run;
  }
  run.gt_trajectory = read_optional<Trajectory>(
      truth / "trajectory.tum", [](const fs::path& p) { return io::read_tum(p); }, run.notes);
  run.gt_extrinsics = read_optional<io::Extrinsics>(
      truth / "extrinsics.yaml", [](const fs::path& p) { return io::read_extrinsics(p); }, run.notes);
  return run;
}

}  // namespace mlidar::report
