#include "mlidar/pipelines/autocalib_search.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "mlidar/core/conversions.hpp"

namespace mlidar::pipelines {
namespace {

/// One search frame: the target's thinned scan and the base's local map around it.
struct SearchFrame {
  std::size_t k = 0;
  std::vector<Eigen::Vector3f> target;  ///< in the target frame
  std::vector<Eigen::Vector3f> sample;  ///< every n-th of target, score_points of them
  Plane ground;                         ///< the reference's, in the base frame at k
  std::unique_ptr<calib::RefSurface> reference;
};

/// Up to `wanted` frames spread evenly over those where both LiDARs have an overlap subsample.
std::vector<std::size_t> search_frame_indices(const BaseLocalMaps& base, const TargetFrames& target, std::size_t wanted) {
  std::vector<std::size_t> usable;
  const auto& trajectory = base.trajectory();
  for (std::size_t k = 0; k < trajectory.stamps.size(); ++k)
    if (!trajectory.lost[k] && target.overlap_points.at(k) && !base.overlap_points(k).empty()) usable.push_back(k);
  std::vector<std::size_t> chosen;
  for (std::size_t i = 0; i < wanted && !usable.empty(); ++i) {
    const std::size_t k = usable[std::min(usable.size() - 1, (2 * i + 1) * usable.size() / (2 * wanted))];
    if (chosen.empty() || chosen.back() != k) chosen.push_back(k);
  }
  return chosen;
}

std::vector<Eigen::Vector3f> thinned_target(const Scan& scan, const StartSearchConfig& config) {
  std::vector<Eigen::Vector3f> near_dropped;
  const float min_range_sq = static_cast<float>(config.min_range_m * config.min_range_m);
  for (const auto& p : scan.points)
    if (p.allFinite() && p.squaredNorm() >= min_range_sq) near_dropped.push_back(p);
  return calib::voxel_downsample(near_dropped, config.target_voxel_m);
}

std::vector<Eigen::Vector3f> strided(const std::vector<Eigen::Vector3f>& points, std::size_t wanted) {
  if (points.size() <= wanted || wanted == 0) return points;
  std::vector<Eigen::Vector3f> out;
  const double stride = static_cast<double>(points.size()) / static_cast<double>(wanted);
  for (std::size_t i = 0; i < wanted; ++i) out.push_back(points[static_cast<std::size_t>(static_cast<double>(i) * stride)]);
  return out;
}

std::optional<SearchFrame> make_frame(const BaseLocalMaps& base, const TargetFrames& target, std::size_t k,
                                      const StartSearchConfig& config) {
  const std::optional<Scan> scan = target.read_scan(k);
  if (!scan) return std::nullopt;
  SearchFrame frame;
  frame.k = k;
  frame.target = thinned_target(*scan, config);
  std::vector<Eigen::Vector3f> reference = base.local_points(k, static_cast<std::size_t>(std::max(config.map_window, 0)));
  const std::optional<Plane> ground = calib::reference_ground(reference, config.coarse);
  if (!ground || frame.target.size() < config.icp.min_matches) return std::nullopt;
  frame.ground = *ground;
  frame.sample = strided(frame.target, config.score_points);
  frame.reference = std::make_unique<calib::RefSurface>(std::move(reference), config.surface);
  return frame;
}

/// Step 3's and 4's score: the share of `points` that land off the reference ground with a reference point within radius.
double score(const SearchFrame& frame, const std::vector<Eigen::Vector3f>& points, const SE3& T_base_target, double radius,
             double ground_band) {
  if (points.empty()) return 0.0;
  const Mat3 R = T_base_target.rotation().toRotationMatrix();
  const Vec3 t = T_base_target.translation();
  const auto radius_sq = static_cast<float>(radius * radius);
  std::size_t matched = 0;
  for (const auto& p : points) {
    const Vec3 q = R * p.cast<double>() + t;
    if (std::abs(frame.ground.signed_distance(q)) < ground_band) continue;
    const auto nearest = frame.reference->tree().knn(q.cast<float>(), 1);
    if (!nearest.empty() && nearest.front().distance_sq <= radius_sq) ++matched;
  }
  return static_cast<double>(matched) / static_cast<double>(points.size());
}

/// The centre of the grid: the guess, or the base LiDAR's position when there is none or it lies too far.
SE3 grid_centre(const std::optional<SE3>& guess, double mount_radius) {
  if (!guess) return SE3::identity();
  if (guess->translation().head<2>().norm() <= mount_radius) return *guess;
  return SE3(guess->rotation(), Vec3::Zero());
}

struct Finalist {
  SE3 T_base_target;
  std::string label;
  double score = 0.0;
};

/// Steps 2-3 on one frame: the best `finalists` starts after their short ICP.
std::vector<Finalist> frame_finalists(SearchFrame& frame, const SE3& centre, const StartSearchConfig& config, std::size_t& starts_count) {
  const std::vector<calib::StartPose> starts = calib::coarse_starts(frame.reference->tree().points(), frame.target, centre, config.coarse);
  starts_count = std::max(starts_count, starts.size());
  // Scored first on a quarter of the sample, then the best `screened` of them on all of it.
  std::vector<std::size_t> order(starts.size());
  std::iota(order.begin(), order.end(), 0);
  const std::vector<Eigen::Vector3f> screen_sample = strided(frame.sample, std::max<std::size_t>(frame.sample.size() / 4, 1));
  std::vector<double> scores(starts.size());
  const auto score_all = [&](const std::vector<Eigen::Vector3f>& sample, std::size_t count) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t i = range.begin(); i != range.end(); ++i)  // each score on its own: the same whatever the threads
        scores[order[i]] = score(frame, sample, starts[order[i]].T_ref_target, config.score_radius_m, config.ground_band_m);
    });
    std::stable_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(count),
                     [&](std::size_t a, std::size_t b) { return scores[a] > scores[b]; });
  };
  score_all(screen_sample, order.size());
  score_all(frame.sample, std::min(order.size(), config.screened));
  std::vector<Finalist> out;
  for (std::size_t i = 0; i < std::min(config.finalists, order.size()); ++i) {
    const calib::StartPose& start = starts[order[i]];
    const calib::IcpResult icp = calib::point_to_plane_icp(*frame.reference, frame.target, start.T_ref_target, config.icp);
    if (!icp.enough_matches) continue;
    out.push_back({icp.T_ref_source, "frame " + std::to_string(frame.k) + ", " + start.label, 0.0});
  }
  return out;
}

bool distinct(const SE3& a, const SE3& b) {
  return rad_to_deg(a.rotation().angularDistance(b.rotation())) > 2.0 || (a.translation() - b.translation()).norm() > 0.2;
}

}  // namespace

StartSearchResult search_refine_start(const BaseLocalMaps& base, const TargetFrames& target, const std::optional<SE3>& guess,
                                      const StartSearchConfig& config) {
  StartSearchResult result;
  std::vector<SearchFrame> frames;
  for (const std::size_t k : search_frame_indices(base, target, config.frames)) {
    if (auto frame = make_frame(base, target, k, config)) frames.push_back(std::move(*frame));
  }
  std::vector<Finalist> finalists;
  const SE3 centre = grid_centre(guess, config.mount_radius_m);
  for (SearchFrame& frame : frames) {
    result.frames.push_back(frame.k);
    for (Finalist& f : frame_finalists(frame, centre, config, result.starts_per_frame)) finalists.push_back(std::move(f));
  }
  for (Finalist& f : finalists) {  // step 4
    for (const SearchFrame& frame : frames)
      f.score += score(frame, frame.target, f.T_base_target, config.final_score_radius_m, config.ground_band_m);
    f.score /= static_cast<double>(frames.size());
  }
  const auto best =
      std::max_element(finalists.begin(), finalists.end(), [](const Finalist& a, const Finalist& b) { return a.score < b.score; });
  if (best == finalists.end()) return result;
  result.T_base_target = best->T_base_target;
  result.label = best->label;
  result.score = best->score;
  for (const Finalist& f : finalists)
    if (distinct(f.T_base_target, best->T_base_target)) result.runner_up_score = std::max(result.runner_up_score, f.score);
  return result;
}

const RefineResult* AppearanceCalibration::result() const {
  if (from_search) return &*from_search;
  return from_start ? &*from_start : nullptr;
}

AppearanceCalibration calibrate_by_appearance(const BaseLocalMaps& base, const TargetFrames& target, const std::optional<SE3>& start,
                                              const RefineConfig& refine, const StartSearchConfig* search) {
  AppearanceCalibration out;
  if (start) out.from_start = refine_against_base(base, target, *start, refine);
  // Hand-eye's translation came out 4-18 m off on bumper LiDARs (lyft on the street) while the refinement from
  // it found no candidate: the appearance search then looks for the start itself.
  if (out.ok() || search == nullptr) return out;
  out.search = search_refine_start(base, target, start, *search);
  if (out.search->T_base_target) out.from_search = refine_against_base(base, target, *out.search->T_base_target, refine);
  return out;
}

}  // namespace mlidar::pipelines
