#pragma once
// metrics.json and map.ply of an odometry run (see odometry_job.hpp).
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mlidar/io/point_covariance_fields.hpp"
#include "mlidar/io/pose_covariance_io.hpp"
#include "mlidar/slam/odometry.hpp"

namespace mlidar::pipelines {

/// {"frames", "lidars", "stages": {NAME: {mean, p50, p95, max} seconds per frame},
///  "total_seconds": {...}, "points_in", "features_out", "degenerate_frames", "retried_frames",
///  "lost_frames", "per_frame": [{stamp, eigenvalues, translation_observability, degenerate, lost, ..., selection}]}
/// Each frame's pose covariance (slam/pose_covariance.hpp, accumulated from the first frame) in
/// pose_covariance.txt's tangent, at the frame's stamp.
std::vector<io::StampedCovariance> pose_covariances(const std::vector<slam::FrameResult>& frames);

/// "x 0.012 m, y 0.015 m, z 0.018 m, rotation 0.04 deg": the 1-sigmas of a pose covariance (pose_covariance.txt's
/// tangent; rotation: the largest axis).
std::string pose_sigma_words(const Mat6& covariance);
/// The terminal's note on the last pose's 1-sigma; after `lost_at_end` lost frames in a row it says the pose is a
/// prediction whose doubt grew with each (so tens of metres after a long run of them are no estimate).
std::string last_pose_note(const Mat6& covariance, std::size_t lost_at_end);

/// The terminal's warning on frames that started a new local map (after `config`'s restart limits); empty for none.
std::string map_restart_warning(const std::vector<std::size_t>& frames, const slam::OdometryConfig& config);

/// metrics.json per frame: `pose_covariance_trace` (m^2 + rad^2) from `covariances` (one per frame).
void add_pose_covariance_traces(nlohmann::json& metrics, const std::vector<io::StampedCovariance>& covariances);

nlohmann::json odometry_metrics_json(const std::vector<slam::FrameResult>& frames, const std::vector<slam::LidarSetup>& lidars);

/// A frame's feature selection (null when off): {method, features, searched, matched, budget, selected,
/// log_det_full and translation_observability_full (null where not evaluated), log_det_selected, degenerate_scene, stopped_by_time,
/// seconds, per_lidar: {NAME: {features, selected}}}. (shared with slam's metrics.json; `selected` is the sum over the LiDARs: the
/// fallback's all).
nlohmann::json selection_json(const std::optional<slam::SelectionSummary>& summary, const std::vector<std::string>& lidar_names);
/// A frame's uncertainty-aware mapping: per LiDAR the features left out for tr(Sigma) > w, and what entered the
/// map; null when it was off (`lidar_uncertain` empty).
nlohmann::json mapping_json(const std::vector<std::size_t>& lidar_uncertain, const std::optional<slam::MappingReport>& mapping,
                            const std::vector<std::string>& lidar_names);

/// The base axis a unit direction lies closest to, in words: "x (forward-backward)",
/// "y (left-right)" or "z (up-down)" (a degenerate registration's weak translation).
std::string base_axis_words(const Vec3& direction_base);

/// A degenerate frame's weak translation in the base frame (zero when the frame is not degenerate).
Vec3 weak_translation_base(const slam::FrameResult& frame);

/// Degenerate frames per weak direction (base_axis_words), most first (ties in order of first appearance).
std::vector<std::pair<std::string, std::size_t>> degenerate_direction_counts(const std::vector<slam::FrameResult>& frames);

/// How the front end made one LiDAR's features over a run.
struct FrontEndTally {
  std::array<std::size_t, 4> frames{};  ///< per slam::RowSource, in its order
  std::vector<int> recovered_rows;      ///< rows of each frame whose rows were recovered, ascending
  std::vector<int> ring_channel_rows;   ///< rows of each frame whose rows came from the ring channel, ascending
  std::size_t frames_from(slam::RowSource source) const { return frames[static_cast<std::size_t>(source)]; }
};
FrontEndTally front_end_tally(const std::vector<slam::FrameResult>& frames, std::size_t lidar);

/// {mean, p50, p95, max} of `values` (zeros when empty).
nlohmann::json timing_summary(std::vector<double> values);

/// The odometry's local maps: plane then edge points and, from uncertainty-aware mapping, their covariances.
struct MapCloud {
  std::vector<Eigen::Vector3f> points;
  std::optional<std::vector<io::UpperCovariance>> covariances;  ///< one per point (m^2)
  std::vector<std::uint8_t> lidars;                             ///< per point the index of the LiDAR that saw it (255: unknown)
  std::vector<std::string> lidar_names;                         ///< index -> name (metrics.json "lidars" order)
};
MapCloud map_cloud(const slam::Odometry& odometry);

/// The odometry's local maps (planes then edges) as a binary PLY, atomically.
void write_map_ply(const std::filesystem::path& path, const slam::Odometry& odometry);
/// A map as a binary PLY with the cov_ fields when it has covariances (io/point_covariance_fields.hpp) and a uchar
/// `lidar` field (index into metrics.json's "lidars"; 255 unknown) when it knows its points' LiDARs, atomically.
void write_map_ply(const std::filesystem::path& path, const MapCloud& map);
/// Points as a binary PLY, atomically.
void write_map_ply(const std::filesystem::path& path, std::vector<Eigen::Vector3f> points);

}  // namespace mlidar::pipelines
