#include "mlidar/slam/odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/median.hpp"
#include "mlidar/slam/pose_covariance.hpp"

namespace mlidar::slam {
namespace {

/// The range 1-sigma for a LiDAR's points: its model's, else the configured one.
double range_sigma(const LidarSetup& lidar, const UncertaintyConfig& ua) {
  return lidar.model.range_noise_sigma > 0.0 ? lidar.model.range_noise_sigma : ua.range_sigma_m;
}

/// RegistrationConfig::plane_min_extent_m for a map built by `lidars`: the noisiest one's range sigma, scaled.
double plane_min_extent(const OdometryConfig& config, const std::vector<LidarSetup>& lidars) {
  double sigma = 0.0;
  for (const LidarSetup& lidar : lidars) sigma = std::max(sigma, range_sigma(lidar, config.uncertainty));
  return config.plane_min_extent_sigmas * sigma;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void append_transformed(const SE3& T, std::span<const Eigen::Vector3f> points, std::vector<Eigen::Vector3f>& out) {
  const std::size_t begin = out.size();
  out.resize(begin + points.size());
  transform_points(T, points, std::span(out).subspan(begin));
}

/// Mean capture time of the frame's points in seconds after its stamp (0 without times).
double mean_point_time(const Frame& frame) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const Scan& scan : frame.scans) {
    if (!scan.has_time()) continue;
    const double shift = scan.stamp - frame.stamp;
    for (const float t : scan.time) sum += static_cast<double>(t) + shift;
    count += scan.time.size();
  }
  return count == 0 ? 0.0 : sum / static_cast<double>(count);
}

/// Every n-th edge and plane of a frame (and their covariances, when given): the retries' coarse pass.
struct StridedFeatures {
  std::vector<Eigen::Vector3f> edges, planes;
  std::vector<PointCovariance> edge_covariances, plane_covariances;
  std::optional<QueryCovariances> query;

  StridedFeatures(const LidarFeatures& features, const QueryCovariances* covariances, std::size_t stride)
      : edges(every_nth(std::span<const Eigen::Vector3f>(features.edges), stride)),
        planes(every_nth(std::span<const Eigen::Vector3f>(features.planes), stride)) {
    if (covariances == nullptr) return;
    edge_covariances = every_nth(covariances->edges, stride);
    plane_covariances = every_nth(covariances->planes, stride);
    query = QueryCovariances{edge_covariances, plane_covariances, covariances->residual_sigma_m};
  }
  StridedFeatures(const StridedFeatures&) = delete;  // `query` points into this object's vectors
  StridedFeatures& operator=(const StridedFeatures&) = delete;
  const QueryCovariances* covariances() const { return query ? &*query : nullptr; }

  template <typename T>
  static std::vector<T> every_nth(std::span<const T> values, std::size_t stride) {
    const std::size_t step = std::max<std::size_t>(stride, 1);
    std::vector<T> out;
    out.reserve(values.size() / step + 1);
    for (std::size_t i = 0; i < values.size(); i += step) out.push_back(values[i]);
    return out;
  }
};

/// Appends one LiDAR's features; a LiDAR without times gets time 0 (no motion) so times stay aligned with points.
void append_features(const LidarFeatures& from, LidarFeatures& to) {
  to.edges.insert(to.edges.end(), from.edges.begin(), from.edges.end());
  to.planes.insert(to.planes.end(), from.planes.begin(), from.planes.end());
  if (from.edge_times.empty())
    to.edge_times.resize(to.edges.size(), 0.0F);
  else
    to.edge_times.insert(to.edge_times.end(), from.edge_times.begin(), from.edge_times.end());
  if (from.plane_times.empty())
    to.plane_times.resize(to.planes.size(), 0.0F);
  else
    to.plane_times.insert(to.plane_times.end(), from.plane_times.begin(), from.plane_times.end());
}

/// Adds the finite values of `values` to sum and count.
void add_finite(std::span<const float> values, double& sum, std::size_t& count) {
  for (const float v : values) {
    if (!std::isfinite(v)) continue;
    sum += v;
    ++count;
  }
}

/// Mean |r| of the matched features of each LiDAR at the registration's last
/// linearisation (NaN: none); `residuals` holds all edges, then all planes, LiDAR after LiDAR.
std::vector<double> mean_residual_per_lidar(const std::vector<LidarFeatures>& lidars, std::span<const float> residuals) {
  std::vector<double> means(lidars.size(), std::numeric_limits<double>::quiet_NaN());
  std::size_t edge_begin = 0;
  std::size_t plane_begin = 0;
  for (const LidarFeatures& f : lidars) plane_begin += f.edges.size();
  for (std::size_t i = 0; i < lidars.size(); ++i) {
    const std::size_t edges = lidars[i].edges.size();
    const std::size_t planes = lidars[i].planes.size();
    if (plane_begin + planes > residuals.size()) break;  // no registration (first frame)
    double sum = 0.0;
    std::size_t count = 0;
    add_finite(residuals.subspan(edge_begin, edges), sum, count);
    add_finite(residuals.subspan(plane_begin, planes), sum, count);
    if (count > 0) means[i] = sum / static_cast<double>(count);
    edge_begin += edges;
    plane_begin += planes;
  }
  return means;
}

/// How many of each LiDAR's features are among the chosen query positions (all edges, then all planes, LiDAR after LiDAR).
std::vector<std::size_t> selected_per_lidar(const std::vector<LidarFeatures>& lidars, std::span<const std::uint32_t> chosen) {
  std::vector<std::size_t> counts(lidars.size(), 0);
  std::vector<std::size_t> edge_end, plane_end;  // cumulative ends of each LiDAR's edges, then planes
  std::size_t end = 0;
  for (const LidarFeatures& f : lidars) edge_end.push_back(end += f.edges.size());
  for (const LidarFeatures& f : lidars) plane_end.push_back(end += f.planes.size());
  for (const std::uint32_t position : chosen) {
    const auto& ends = position < edge_end.back() ? edge_end : plane_end;
    ++counts[static_cast<std::size_t>(std::upper_bound(ends.begin(), ends.end(), position) - ends.begin())];
  }
  return counts;
}

void clear_features(LidarFeatures& f) {
  f.edges.clear();
  f.planes.clear();
  f.edge_times.clear();
  f.plane_times.clear();
}

/// Features deskewed (to the base at their reference stamp) with no motion, deskewed again with `velocity`.
void deskew_again(const BodyVelocity& velocity, LidarFeatures& f) {
  const std::vector<Eigen::Vector3f> edges = f.edges, planes = f.planes;
  deskew_to_base(edges, f.edge_times, {}, SE3::identity(), velocity, f.edges);
  deskew_to_base(planes, f.plane_times, {}, SE3::identity(), velocity, f.planes);
}

}  // namespace

std::optional<SelectionSummary> FrameResult::selection_summary() const {
  if (!registration.selection) return std::nullopt;
  SelectionSummary summary{*registration.selection, lidar_features, lidar_selected, full_set_degeneracy, degenerate_scene};
  summary.report.chosen = {};
  return summary;
}

Odometry::Odometry(OdometryConfig config, std::vector<LidarSetup> lidars)
    : config_(std::move(config)),
      lidars_(std::move(lidars)),
      workspaces_(lidars_.size()),
      features_(lidars_.size()),
      edge_map_(config_.edge_voxel_m, config_.edge_points_per_voxel),
      plane_map_(config_.plane_voxel_m, config_.plane_points_per_voxel),
      recent_residuals_(config_.trust.residual_history),
      registration_(config_.registration) {
  if (lidars_.empty()) throw std::invalid_argument("Odometry: no LiDARs");
  config_.registration.plane_min_extent_m = plane_min_extent(config_, lidars_);  // registration_ is set per frame
}

void Odometry::set_lidars(std::vector<LidarSetup> lidars) {
  if (lidars.empty()) throw std::invalid_argument("Odometry::set_lidars: no LiDARs");
  lidars_ = std::move(lidars);
  config_.registration.plane_min_extent_m = plane_min_extent(config_, lidars_);
  workspaces_ = std::vector<FrontEndWorkspace>(lidars_.size());
  features_ = std::vector<LidarFeatures>(lidars_.size());
}

namespace {

/// The constant velocity that moves the base from `from` to `to` (zero unless `to` is later).
BodyVelocity velocity_between(const StampedPose& from, const StampedPose& to) {
  if (!(to.stamp > from.stamp)) return {};
  return BodyVelocity::from_relative_pose(from.T_world_base.inverse() * to.T_world_base, to.stamp - from.stamp);
}

/// World points and covariances of one block's features (eq 4.29 through the LiDAR's compounded world pose).
void append_covariant(const UncertainPose& T_world_lidar, const SE3& T_lidar_base, const SE3& T_world_base,
                      std::span<const Eigen::Vector3f> points_base, double range_sigma_m, double angular_sigma_rad, std::uint8_t source,
                      std::vector<CovariantPoint>& out) {
  const BeamPointCovariance covariance_of(T_world_lidar, range_sigma_m, angular_sigma_rad);
  for (const Eigen::Vector3f& p : points_base) {
    const Vec3 p_base = p.cast<double>();
    out.push_back({(T_world_base * p_base).cast<float>(), PointCovariance::from(covariance_of(T_lidar_base * p_base)), source});
  }
}

/// The map's record of LiDAR `index` (VoxelMap::sources), saturated at kNoSource.
std::uint8_t lidar_source(std::size_t index) { return static_cast<std::uint8_t>(std::min<std::size_t>(index, VoxelMap::kNoSource)); }

/// Drops the points with tr(Sigma) > w (sec 4.8.2) and returns how many it dropped; adds every offered trace to `traces`.
std::size_t drop_uncertain(double trace_threshold_m2, std::vector<CovariantPoint>& points, std::vector<double>& traces) {
  const std::size_t before = points.size();
  for (const CovariantPoint& p : points) traces.push_back(p.covariance.trace());
  std::erase_if(points, [&](const CovariantPoint& p) { return !(p.covariance.trace() <= trace_threshold_m2); });
  return before - points.size();
}

}  // namespace

std::optional<MappingReport> Odometry::update_map(const SE3& T_world_centroid, const LidarFeatures& features,
                                                  const std::vector<FeatureBlock>& blocks, const Mat6& Xi_reg) {
  std::optional<MappingReport> report;
  const UncertaintyConfig& ua = config_.uncertainty;
  if (!ua.enabled) {
    std::vector<std::uint8_t> edge_sources, plane_sources;  // blocks are the LiDARs in order
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      edge_sources.insert(edge_sources.end(), blocks[b].edges, lidar_source(b));
      plane_sources.insert(plane_sources.end(), blocks[b].planes, lidar_source(b));
    }
    if (edge_sources.size() != features.edges.size() || plane_sources.size() != features.planes.size())
      throw std::logic_error("Odometry::update_map: feature blocks do not cover the features");
    std::vector<Eigen::Vector3f> world;
    append_transformed(T_world_centroid, features.edges, world);
    edge_map_.add(world, edge_sources);
    world.clear();
    append_transformed(T_world_centroid, features.planes, world);
    plane_map_.add(world, plane_sources);
  } else {
    // Sec 4.8.1-4.8.2: each LiDAR's world pose compounded (fourth order), each point's Sigma, tr(Sigma) <= w, eq 4.30.
    std::vector<CovariantPoint> edges, planes;
    std::size_t edge_at = 0, plane_at = 0;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const FeatureBlock& block = blocks[b];
      const std::uint8_t source = lidar_source(b);
      const UncertainPose T_world_lidar = compound({T_world_centroid, Xi_reg}, block.T_base_lidar);
      const SE3 T_lidar_base = block.T_base_lidar.T.inverse();
      append_covariant(T_world_lidar, T_lidar_base, T_world_centroid, std::span(features.edges).subspan(edge_at, block.edges),
                       block.range_sigma_m, ua.angular_sigma_rad, source, edges);
      append_covariant(T_world_lidar, T_lidar_base, T_world_centroid, std::span(features.planes).subspan(plane_at, block.planes),
                       block.range_sigma_m, ua.angular_sigma_rad, source, planes);
      edge_at += block.edges;
      plane_at += block.planes;
    }
    if (edge_at != features.edges.size() || plane_at != features.planes.size())
      throw std::logic_error("Odometry::update_map: feature blocks do not cover the features");
    report.emplace();
    report->features = edges.size() + planes.size();
    std::vector<double> traces;
    report->dropped_uncertain =
        drop_uncertain(ua.trace_threshold_m2, edges, traces) + drop_uncertain(ua.trace_threshold_m2, planes, traces);
    report->median_trace_m2 = traces.empty() ? 0.0 : median(traces);
    if (ua.voxel_filter_m > 0.0) {
      edges = covariance_voxel_filter(edges, ua.voxel_filter_m, ua.trace_threshold_m2);
      planes = covariance_voxel_filter(planes, ua.voxel_filter_m, ua.trace_threshold_m2);
    }
    report->points_added = edges.size() + planes.size();
    edge_map_.add(edges);
    plane_map_.add(planes);
  }
  const Eigen::Vector3f origin = T_world_centroid.translation().cast<float>();
  edge_map_.remove_far(origin, config_.local_map_radius_m);
  plane_map_.remove_far(origin, config_.local_map_radius_m);
  return report;
}

void Odometry::restart_with_first_velocity(double first_centroid_time, bool second_unmapped) {
  const BodyVelocity velocity = latest_velocity();
  // World so far: the base at the first centroid (at T_world_origin_), whose pose from the first stamp is Exp(t_c v):
  // the first stamp's pose becomes T_world_origin_.
  const SE3 T_stamp_centroid = velocity.pose_at(first_centroid_time);
  const SE3 shift = T_world_origin_ * T_stamp_centroid * T_world_origin_.inverse();
  for (auto& pose : centroid_poses_) pose.T_world_base = shift * pose.T_world_base;
  last_registered_.T_world_base = shift * last_registered_.T_world_base;
  velocity_ = velocity_between(centroid_poses_.front(), last_registered_);  // the same, in the new world (zero: second lost)
  edge_map_ = VoxelMap(config_.edge_voxel_m, config_.edge_points_per_voxel);
  plane_map_ = VoxelMap(config_.plane_voxel_m, config_.plane_points_per_voxel);
  // The first frame defines the world (no pose doubt); the second is registered against it alone, its
  // pose doubt left out too.
  deskew_again(velocity, first_features_);
  update_map(centroid_poses_.front().T_world_base, first_features_, first_blocks_, Mat6::Zero());
  if (!second_unmapped) {
    deskew_again(velocity, frame_features_);
    update_map(centroid_poses_.back().T_world_base, frame_features_, frame_blocks_, Mat6::Zero());
  }
  clear_features(first_features_);
}

void Odometry::adapt_threshold(const SE3& prediction, const SE3& estimate) {
  const SE3 error = prediction.inverse() * estimate;
  const double angle = so3_log(error.rotation()).norm();
  const double metres = error.translation().norm() + 2.0 * config_.reference_range_m * std::sin(angle / 2.0);
  error_sq_sum_ += metres * metres;
  ++error_count_;
}

RegistrationConfig Odometry::frame_registration(const SE3& prediction, double threshold, double centroid_stamp, FrameResult& frame) {
  RegistrationConfig config = config_.registration;
  if (mostly_voxel_samples()) config.plane_neighbors_max = config_.voxel_plane_neighbors_max;
  SelectionConfig& selection = config.selection;
  if (selection_paused_ || centroid_stamp - velocity_anchor().stamp > selection.max_frame_gap_s) selection.method = SelectionMethod::kNone;
  if (selection.method == SelectionMethod::kNone || !selection.adaptive) return config;
  if (centroid_stamp - degeneracy_stamp_ >= selection.degeneracy_interval_s) {
    frame.full_set_degeneracy = full_set_degeneracy(frame_features_.edges, frame_features_.planes, edge_map_, plane_map_, prediction,
                                                    threshold, config_.registration);
    degenerate_scene_ = degenerate_scene(*frame.full_set_degeneracy, selection);
    degeneracy_stamp_ = centroid_stamp;
  }
  frame.degenerate_scene = degenerate_scene_;
  if (degenerate_scene_) selection.ratio = selection.degenerate_ratio;
  return config;
}

double Odometry::voxel_sample_share() const {
  std::size_t voxel_samples = 0;
  for (const LidarFeatures& f : features_) voxel_samples += f.voxel_samples;
  const std::size_t all = frame_features_.edges.size() + frame_features_.planes.size();
  return all > 0 ? static_cast<double>(voxel_samples) / static_cast<double>(all) : 0.0;
}

double Odometry::residual_scale() const { return 1.0 + (config_.trust.voxel_residual_ratio - 1.0) * voxel_sample_share(); }

TrustRule Odometry::trust_rule() const {
  // The second frame of a map (at the run's start or after start_over) matches the first sweep alone.
  const double recent_median_m = recent_residuals_.size() >= config_.trust.min_residual_history ? recent_residuals_.median_m()
                                                                                                : std::numeric_limits<double>::quiet_NaN();
  return {config_.trust, residual_scale() * recent_median_m, centroid_poses_.size() == 1};
}

void Odometry::refine_deskew(const BodyVelocity& used, double centroid_stamp, FrameResult& result) {
  // Eq 4.12 again with the velocity from the last registered centroid to this registration: the
  // predicted one lags a frame, which left the map (and an auxiliary LiDAR calibrated
  // against it) with a shared error under handheld motion (docs/benchmarks.md).
  const BodyVelocity measured = velocity_between(velocity_anchor(), {centroid_stamp, result.registration.T_world_base});
  redeskew(frame_features_.edge_times, used, measured, frame_features_.edges);
  redeskew(frame_features_.plane_times, used, measured, frame_features_.planes);
  result.registration =
      register_scan_to_map(frame_features_.edges, frame_features_.planes, edge_map_, plane_map_, result.registration.T_world_base,
                           result.threshold_m, registration_, nullptr, query_covariances());
}

void Odometry::apply_registered_deskew(const BodyVelocity& used, const BodyVelocity& registered) {
  redeskew(frame_features_.edge_times, used, registered, frame_features_.edges);
  redeskew(frame_features_.plane_times, used, registered, frame_features_.planes);
  for (LidarFeatures& f : features_) {
    redeskew(f.edge_times, used, registered, f.edges);
    redeskew(f.plane_times, used, registered, f.planes);
  }
}

void Odometry::add_retries(const SE3& prediction, double threshold, const MotionDeskew* motion,
                           std::vector<RegistrationResult>& out) const {
  std::vector<SE3> starts;
  const auto add_turned = [&](const SE3& around) {
    for (const double yaw_deg : config_.retry_yaw_deg)
      starts.push_back(around * SE3(so3_exp(Vec3(0, 0, deg_to_rad(yaw_deg))), Vec3::Zero()));
  };
  add_turned(prediction);
  if (config_.retry_from_previous_pose) {
    starts.push_back(centroid_poses_.back().T_world_base);
    add_turned(centroid_poses_.back().T_world_base);
  }
  // Every feature in the retries: they are for frames whose first registration
  // was not trusted, where a selection made at a poor start is least reliable.
  RegistrationConfig every_feature = registration_;
  every_feature.selection.method = SelectionMethod::kNone;
  // A coarse pass from each start with the initial (wide) threshold on every n-th feature ...
  const RegistrationConfig coarse_config = coarse_registration();
  const StridedFeatures sparse(frame_features_, query_covariances(), config_.retry_coarse_stride);
  std::vector<RegistrationResult> coarse(starts.size());
  // Independent of each other (the maps are only read), so in parallel; each lands in its own slot.
  tbb::parallel_for(std::size_t{0}, starts.size(), [&](std::size_t i) {
    coarse[i] = register_scan_to_map(sparse.edges, sparse.planes, edge_map_, plane_map_, starts[i],
                                     std::max(threshold, config_.initial_threshold_m), coarse_config, nullptr, sparse.covariances());
  });
  // ... then a fine pass on every feature from each distinct coarse end pose that may still fit.
  const std::vector<SE3> distinct = distinct_poses(refinable_poses(coarse, config_.trust.max_mean_residual_m),
                                                   0.25 * config_.trust.distinct_translation_m, 0.25 * config_.trust.distinct_rotation_deg);
  const std::size_t first = out.size();
  out.resize(first + distinct.size());
  tbb::parallel_for(std::size_t{0}, distinct.size(), [&](std::size_t i) {
    out[first + i] = register_scan_to_map(frame_features_.edges, frame_features_.planes, edge_map_, plane_map_, distinct[i], threshold,
                                          every_feature, motion, query_covariances());
  });
}

RegistrationConfig Odometry::coarse_registration() const {
  RegistrationConfig coarse = registration_;
  coarse.selection.method = SelectionMethod::kNone;
  coarse.max_iterations = config_.retry_coarse_iterations;
  coarse.convergence_translation_m = config_.retry_coarse_convergence_m;
  coarse.convergence_rotation_rad = config_.retry_coarse_convergence_rad;
  return coarse;
}

SE3 Odometry::registration_start(const SE3& prediction, double threshold) const {
  if (config_.voxel_coarse_stride <= 1 || !mostly_voxel_samples()) return prediction;
  // The coarse pass keeps the prediction along a translation its features do not observe (scan_to_map), so the
  // full registration from its end still holds the prediction's value there.
  const StridedFeatures sparse(frame_features_, query_covariances(), static_cast<std::size_t>(config_.voxel_coarse_stride));
  const RegistrationResult coarse = register_scan_to_map(sparse.edges, sparse.planes, edge_map_, plane_map_, prediction, threshold,
                                                         coarse_registration(), nullptr, sparse.covariances());
  return coarse.converged ? coarse.T_world_base : prediction;
}

RegistrationResult Odometry::register_robustly(const SE3& prediction, double centroid_stamp, const MotionDeskew* motion,
                                               FrameResult& frame) {
  const double threshold = error_count_ == 0
                               ? config_.initial_threshold_m
                               : std::max(config_.min_threshold_m, 3.0 * std::sqrt(error_sq_sum_ / static_cast<double>(error_count_)));
  frame.threshold_m = threshold;
  registration_ = frame_registration(prediction, threshold, centroid_stamp, frame);
  const TrustRule rule = trust_rule();
  frame.recent_residual_m = rule.recent_median_m;
  std::vector<RegistrationResult> candidates;
  candidates.push_back(register_scan_to_map(frame_features_.edges, frame_features_.planes, edge_map_, plane_map_,
                                            registration_start(prediction, threshold), threshold, registration_, motion,
                                            query_covariances()));
  // After a long gap the constant-velocity prediction says little, and one
  // alignment that fits is no evidence that it is the only one: the retries
  // run and decide, rivals included.
  const bool long_gap = centroid_stamp - velocity_anchor().stamp > config_.always_retry_after_s;
  if (rule.trusted(candidates.front()) && !long_gap) {
    frame.trust = judge_degenerate(Trust::kTrusted, candidates.front(), prediction);
    if (frame.trust == Trust::kTrusted) return std::move(candidates.front());
  }
  // Every retry runs (not only up to the first trusted one): the first to pass
  // may be a wrong alignment that a later start beats, and the rivals say whether the best is unique.
  frame.retried = true;
  add_retries(prediction, threshold, motion, candidates);
  const Choice choice = choose_registration(candidates, rule);
  frame.trust = judge_degenerate(choice.trust, candidates[choice.best], prediction);
  return std::move(candidates[choice.best]);
}

Trust Odometry::judge_degenerate(Trust trust, const RegistrationResult& r, const SE3& prediction) const {
  trust = judge_degenerate_correction(trust, r, prediction, config_.trust);
  // A degenerate registration keeps the prediction along what it does not observe; after a flagged or lost frame that
  // prediction comes from poses that may be wrong (a 2 s gap: frames trusted 3.4 m / 31 deg off, docs/benchmarks.md).
  if (trust == Trust::kTrusted && r.degenerate && !last_frame_trusted_) return Trust::kDegenerate;
  return trust;
}

namespace {

/// Keeps the entries of `values` whose `keep` is true (times may be empty: nothing to filter).
template <typename T>
void keep_where(const std::vector<bool>& keep, std::vector<T>& values) {
  if (values.empty()) return;
  std::size_t out = 0;
  for (std::size_t i = 0; i < values.size(); ++i)
    if (keep[i]) values[out++] = values[i];
  values.resize(out);
}

/// One LiDAR's features with tr(Sigma_b) <= w (their covariances alongside); returns how many it dropped.
std::size_t drop_uncertain_features(double trace_threshold_m2, LidarFeatures& f, std::vector<PointCovariance>& edge_covariances,
                                    std::vector<PointCovariance>& plane_covariances) {
  const auto certain = [&](const std::vector<PointCovariance>& covariances) {
    std::vector<bool> keep(covariances.size());
    for (std::size_t i = 0; i < covariances.size(); ++i) keep[i] = covariances[i].trace() <= trace_threshold_m2;
    return keep;
  };
  const std::size_t before = f.edges.size() + f.planes.size();
  const std::vector<bool> keep_edges = certain(edge_covariances), keep_planes = certain(plane_covariances);
  // The voxel samples are the last of the planes.
  f.voxel_samples =
      static_cast<std::size_t>(std::count(keep_planes.end() - static_cast<std::ptrdiff_t>(f.voxel_samples), keep_planes.end(), true));
  keep_where(keep_edges, f.edges);
  keep_where(keep_edges, f.edge_times);
  keep_where(keep_edges, edge_covariances);
  keep_where(keep_planes, f.planes);
  keep_where(keep_planes, f.plane_times);
  keep_where(keep_planes, plane_covariances);
  return before - f.edges.size() - f.planes.size();
}

}  // namespace

void Odometry::collect_features(FrameResult& result) {
  clear_features(frame_features_);
  frame_blocks_.clear();
  const UncertaintyConfig& ua = config_.uncertainty;
  std::vector<std::vector<PointCovariance>> edge_covariances(lidars_.size()), plane_covariances(lidars_.size());
  if (ua.enabled) {
    // Eq 4.29 in the base frame for every feature (extrinsic and sensor noise; the base pose is what is solved for);
    // those with tr(Sigma) > w are left out of the registration and the map (sec 4.8.2).
    result.lidar_uncertain.assign(lidars_.size(), 0);
    tbb::parallel_for(std::size_t{0}, lidars_.size(), [&](std::size_t i) {
      const UncertainPose T_base_lidar{lidars_[i].T_base_lidar, lidars_[i].extrinsic_covariance};
      edge_covariances[i] = feature_covariances(features_[i].edges, T_base_lidar, range_sigma(lidars_[i], ua), ua.angular_sigma_rad);
      plane_covariances[i] = feature_covariances(features_[i].planes, T_base_lidar, range_sigma(lidars_[i], ua), ua.angular_sigma_rad);
      result.lidar_uncertain[i] = drop_uncertain_features(ua.trace_threshold_m2, features_[i], edge_covariances[i], plane_covariances[i]);
    });
  }
  for (std::size_t i = 0; i < lidars_.size(); ++i) {
    result.lidar_features.push_back(features_[i].edges.size() + features_[i].planes.size());
    result.lidar_rows.push_back(features_[i].rows);
    result.lidar_row_source.push_back(features_[i].row_source);
    append_features(features_[i], frame_features_);
    frame_blocks_.push_back({features_[i].edges.size(), features_[i].planes.size(),
                             UncertainPose{lidars_[i].T_base_lidar, lidars_[i].extrinsic_covariance}, range_sigma(lidars_[i], ua)});
  }
  result.edge_features = frame_features_.edges.size();
  result.plane_features = frame_features_.planes.size();
  query_covariances_.reset();
  if (!ua.enabled) return;
  edge_covariances_.clear();
  plane_covariances_.clear();
  for (std::size_t i = 0; i < lidars_.size(); ++i) {
    edge_covariances_.insert(edge_covariances_.end(), edge_covariances[i].begin(), edge_covariances[i].end());
    plane_covariances_.insert(plane_covariances_.end(), plane_covariances[i].begin(), plane_covariances[i].end());
  }
  query_covariances_ = QueryCovariances{edge_covariances_, plane_covariances_, ua.residual_sigma_m};
}

FrameResult Odometry::process(const Frame& frame) {
  if (frame.scans.size() != lidars_.size())
    throw std::invalid_argument("Odometry::process: frame has a different number of scans than LiDARs");
  FrameResult result;
  result.stamp = frame.stamp;
  result.centroid_time = mean_point_time(frame);
  const double centroid_stamp = frame.stamp + result.centroid_time;
  if (restart_due(frame)) {
    start_over(predicted_centroid_pose(centroid_stamp));
    result.map_restarted = true;
  }
  const BodyVelocity velocity = latest_velocity();
  const SE3 prediction = predicted_centroid_pose(centroid_stamp);

  std::vector<StageSeconds> per_lidar(lidars_.size(), StageSeconds{});
  tbb::parallel_for(std::size_t{0}, lidars_.size(), [&](std::size_t i) {
    run_front_end(frame.scans[i], centroid_stamp, lidars_[i], velocity, config_.front_end, workspaces_[i], features_[i], per_lidar[i]);
  });
  for (std::size_t i = 0; i < lidars_.size(); ++i) {
    for (std::size_t s = 0; s < kStageCount; ++s) result.seconds[s] += per_lidar[i][s];
    result.points_in += frame.scans[i].size();
  }
  collect_features(result);

  auto start = std::chrono::steady_clock::now();
  SE3 T_world_centroid = SE3::identity();
  if (centroid_poses_.empty()) {
    result.registration.converged = true;
    T_world_centroid = T_world_origin_;
  } else {
    std::optional<MotionDeskew> motion;
    if (config_.deskew_in_registration && centroid_poses_.size() >= 2 && centroid_stamp > velocity_anchor().stamp)
      motion = MotionDeskew{frame_features_.edge_times, frame_features_.plane_times, velocity_anchor().T_world_base,
                            centroid_stamp - velocity_anchor().stamp, velocity};
    result.registration = register_robustly(prediction, centroid_stamp, motion ? &*motion : nullptr, result);
    const BodyVelocity deskewed_with = result.registration.velocity_used.value_or(velocity);
    if (result.registration.velocity_used) apply_registered_deskew(velocity, deskewed_with);
    if (config_.refine_deskew && centroid_poses_.size() >= 2 && result.trust == Trust::kTrusted)
      refine_deskew(deskewed_with, centroid_stamp, result);
    T_world_centroid = result.registration.T_world_base;
    result.lidar_mean_residual_m = mean_residual_per_lidar(features_, result.registration.residuals_m);
    if (result.registration.selection) result.lidar_selected = selected_per_lidar(features_, result.registration.selection->chosen);
    if (result.lost())
      T_world_centroid = prediction;  // flagged, not silently trusted
    else if (result.trust == Trust::kTrusted &&
             (prediction.inverse() * centroid_poses_.back().T_world_base).translation().norm() >= config_.min_motion_m)
      adapt_threshold(prediction, T_world_centroid);
  }
  result.seconds[static_cast<std::size_t>(Stage::kRegistration)] += seconds_since(start);

  start = std::chrono::steady_clock::now();
  if (centroid_poses_.empty()) {
    // No velocity yet: the first frame is mapped undeskewed and deskewed again once frame 2 gives one.
    first_stamp_ = frame.stamp;
    first_features_ = frame_features_;
    first_blocks_ = frame_blocks_;
  }
  push_centroid_pose({centroid_stamp, T_world_centroid}, centroid_poses_.empty() || !result.lost());
  if (segment_frames_ == 2) {
    restart_with_first_velocity(centroid_poses_.front().stamp - first_stamp_, result.flagged());
    result.registration.T_world_base = centroid_poses_.back().T_world_base;
  } else if (result.trust == Trust::kTrusted) {
    // The first frame defines the world: no pose doubt.
    const bool registered = segment_frames_ > 1;
    const Mat6 Xi_reg =
        config_.uncertainty.enabled && registered ? registration_covariance(result.registration, MotionPriorSigma{}) : Mat6::Zero();
    result.mapping = update_map(T_world_centroid, frame_features_, frame_blocks_, Xi_reg);
  }
  // Every registered frame, suspect ones too: a lasting change of the fit (a rougher scene) moves the
  // median within half the history instead of leaving every later frame suspect and the map frozen.
  if (centroid_poses_.size() >= 2 && !result.lost()) recent_residuals_.add(result.registration.mean_residual_m / residual_scale());
  result.seconds[static_cast<std::size_t>(Stage::kMapUpdate)] += seconds_since(start);
  result.T_world_base = centroid_poses_.back().T_world_base * latest_velocity().pose_at(-result.centroid_time);
  last_frame_trusted_ = segment_frames_ == 1 || result.trust == Trust::kTrusted;  // a map's first frame defines its world
  if (result.map_restarted) {
    result.trust = Trust::kLost;  // mapped as the new map's first frame, its pose a prediction
  } else {
    count_untrusted(result);
  }
  return result;
}

SE3 Odometry::predicted_centroid_pose(double centroid_stamp) const {
  if (centroid_poses_.empty()) return T_world_origin_;
  return centroid_poses_.back().T_world_base * latest_velocity().pose_at(centroid_stamp - centroid_poses_.back().stamp);
}

void Odometry::count_untrusted(const FrameResult& result) {
  if (result.trust == Trust::kTrusted) untrusted_in_a_row_ = 0;
  if (!result.lost()) lost_in_a_row_ = 0;
  // A frame without features (e.g. a gap in the input) is no evidence either way.
  if (result.trust == Trust::kTrusted || result.edge_features + result.plane_features == 0) return;
  ++untrusted_in_a_row_;
  if (result.lost()) ++lost_in_a_row_;
  failed_on_voxel_samples_ = mostly_voxel_samples();
}

bool Odometry::restart_due(const Frame& frame) const {
  const auto reached = [](std::size_t count, std::size_t limit) { return limit > 0 && count >= limit; };
  if (!reached(lost_in_a_row_, config_.restart_after_lost) && !reached(untrusted_in_a_row_, config_.restart_after_suspect)) return false;
  if (failed_on_voxel_samples_) return false;  // keyframes without scan rows do not restart
  return std::any_of(frame.scans.begin(), frame.scans.end(), [](const Scan& scan) { return !scan.empty(); });
}

void Odometry::push_centroid_pose(const StampedPose& pose, bool registered) {
  if (registered) {
    if (!centroid_poses_.empty()) velocity_ = velocity_between(last_registered_, pose);
    last_registered_ = pose;
  }
  // The prediction needs the last; the second frame of a map also the first.
  if (centroid_poses_.size() == 2) centroid_poses_.erase(centroid_poses_.begin());
  centroid_poses_.push_back(pose);
  ++segment_frames_;
}

void Odometry::start_over(const SE3& T_world_origin) {
  T_world_origin_ = T_world_origin;
  centroid_poses_.clear();
  velocity_ = {};
  segment_frames_ = 0;
  edge_map_ = VoxelMap(config_.edge_voxel_m, config_.edge_points_per_voxel);
  plane_map_ = VoxelMap(config_.plane_voxel_m, config_.plane_points_per_voxel);
  degeneracy_stamp_ = -std::numeric_limits<double>::infinity();
  degenerate_scene_ = false;
  error_sq_sum_ = 0.0;
  error_count_ = 0;
  lost_in_a_row_ = 0;
  untrusted_in_a_row_ = 0;
}

}  // namespace mlidar::slam
