#include "mlidar/slam/scan_to_map.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <Eigen/Eigenvalues>

#include "mlidar/slam/map_matcher.hpp"
#include "mlidar/slam/residuals.hpp"

namespace mlidar::slam {
namespace {

/// Sums of one Gauss-Newton linearisation.
struct NormalEquations {
  Mat6 H = Mat6::Zero();
  Vec6 g = Vec6::Zero();
  double residual_sum = 0.0;
  std::size_t planes = 0;
  std::size_t edges = 0;

  /// One scalar row (plane_row), weight w.
  void add(const PlaneRow& row, double w) {
    H.noalias() += (w * row.jacobian) * row.jacobian.transpose();
    g.noalias() += (w * row.residual) * row.jacobian;
  }
  NormalEquations& operator+=(const NormalEquations& o) {
    H += o.H;
    g += o.g;
    residual_sum += o.residual_sum;
    planes += o.planes;
    edges += o.edges;
    return *this;
  }
};

/// A feature's last map search: where it was (world) and what it found.
template <typename Model>
struct CachedMatch {
  Vec3 where = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  ///< NaN: never searched
  std::optional<Model> model;
};

/// The map correspondences of every feature across iterations: a feature is
/// searched again only once it has moved more than the rematch distance from
/// where it was last searched (near convergence the pose moves millimetres and
/// the same map neighbours come back); the residual is always re-evaluated.
struct MatchCache {
  std::vector<CachedMatch<MapLine>> edges;
  std::vector<CachedMatch<PlaneCoefficients>> planes;
};

FeatureInformation rank_one(const Vec6& row) {
  FeatureInformation f;
  f.rows.col(0) = row;
  return f;
}

FeatureInformation rank_two(const Vec6& first, const Vec6& second) {
  FeatureInformation f;
  f.rows << first, second;
  f.rank = 2;
  return f;
}

struct Matcher {
  const VoxelMap& edge_map;
  const VoxelMap& plane_map;
  const SE3& T;
  const RegistrationConfig& config;
  float neighborhood_sq;  ///< squared search radius for the map neighbours
  double max_residual_m;  ///< correspondences with a larger |r| are rejected
  double huber_delta;
  double rematch_sq;           ///< squared rematch distance
  MatchCache& cache;           ///< each feature's entry is touched by one task only
  std::span<float> residuals;  ///< |r| per query (edges, then planes), NaN when unmatched
  /// When screening for feature selection: each query's weighted rows (rank 0: unmatched); else empty.
  std::span<FeatureInformation> information;
  /// Eq 4.23: each query's covariance (base frame) and sigma_0^2; empty: unweighted.
  std::span<const PointCovariance> edge_covariances = {};
  std::span<const PointCovariance> plane_covariances = {};
  double residual_sigma_sq = 0.0;

  /// The uncertainty weight of query i's row with world normal n (1 without covariances).
  double uncertainty(std::span<const PointCovariance> covariances, std::size_t i, const Vec3& n_world) const {
    if (covariances.empty()) return 1.0;
    return uncertainty_weight(covariances[i], T.rotation().conjugate() * n_world, residual_sigma_sq);
  }

  template <typename Model, typename Search>
  const std::optional<Model>& lookup(CachedMatch<Model>& cached, const Vec3& q, Search search) const {
    if (!((q - cached.where).squaredNorm() <= rematch_sq)) {
      cached.where = q;
      cached.model = search();
    }
    return cached.model;
  }

  void plane(std::size_t i, const Eigen::Vector3f& p, NormalEquations& eq) const {
    residuals[cache.edges.size() + i] = std::numeric_limits<float>::quiet_NaN();
    const Vec3 q = T * Vec3(p.cast<double>());
    const std::optional<PlaneCoefficients>& plane =
        lookup(cache.planes[i], q, [&] { return match_plane(plane_map, q, neighborhood_sq, config); });
    if (!plane) return;
    // Eq 4.7 as its equivalent scalar row (residuals.hpp).
    const PlaneRow row = plane_row(*plane, q);
    const double norm = std::abs(row.residual);
    if (norm > max_residual_m) return;
    const double w = huber_weight(norm, huber_delta) * uncertainty(plane_covariances, i, plane->normal);
    eq.add(row, w);
    eq.residual_sum += norm;
    residuals[cache.edges.size() + i] = static_cast<float>(norm);
    if (!information.empty()) information[cache.edges.size() + i] = rank_one(std::sqrt(w) * row.jacobian);
    ++eq.planes;
  }

  void edge(std::size_t i, const Eigen::Vector3f& p, NormalEquations& eq) const {
    residuals[i] = std::numeric_limits<float>::quiet_NaN();
    const Vec3 q = T * Vec3(p.cast<double>());
    const std::optional<MapLine>& line = lookup(cache.edges[i], q, [&] { return match_line(edge_map, q, neighborhood_sq, config); });
    if (!line) return;
    // Eq 4.8: the two perpendicular planes through the line, one scalar row each.
    const EdgePlanes planes = edge_planes(line->point, line->direction, q);
    const PlaneRow first = plane_row(planes.first, q), second = plane_row(planes.second, q);
    const double norm = std::hypot(first.residual, second.residual);
    if (norm > max_residual_m) return;
    const double w = huber_weight(norm, huber_delta);
    const double w_first = w * uncertainty(edge_covariances, i, planes.first.normal);
    const double w_second = w * uncertainty(edge_covariances, i, planes.second.normal);
    eq.add(first, w_first);
    eq.add(second, w_second);
    eq.residual_sum += norm;
    residuals[i] = static_cast<float>(norm);
    if (!information.empty()) information[i] = rank_two(std::sqrt(w_first) * first.jacobian, std::sqrt(w_second) * second.jacobian);
    ++eq.edges;
  }
};

NormalEquations linearise(std::span<const Eigen::Vector3f> edges, std::span<const Eigen::Vector3f> planes, const Matcher& matcher) {
  const std::size_t total = edges.size() + planes.size();
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, total, 256), NormalEquations{},
      [&](const tbb::blocked_range<std::size_t>& range, NormalEquations eq) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          if (i < edges.size()) {
            matcher.edge(i, edges[i], eq);
          } else {
            matcher.plane(i - edges.size(), planes[i - edges.size()], eq);
          }
        }
        return eq;
      },
      [](NormalEquations a, const NormalEquations& b) { return a += b; });
}

/// Degeneracy at the solution. Early iterations, far from it, may match mostly
/// one surface (the ground), so this is judged once, at the end: the
/// correction from `initial` loses its translation along the weak direction.
void keep_initial_along_weak_translation(const SE3& initial, double threshold, RegistrationResult& result) {
  // Translation block of H: sum w J_t^T J_t = sum w n n^T over the residual normals.
  const Eigen::SelfAdjointEigenSolver<Mat3> translation(result.hessian.topLeftCorner<3, 3>());
  const Vec3 spread = translation.eigenvalues();
  result.translation_observability = spread(2) > 0.0 ? spread(0) / spread(2) : 0.0;
  result.degenerate = result.translation_observability < threshold;
  if (!result.degenerate) return;
  Vec6 correction = (result.T_world_base * initial.inverse()).log();
  const Vec3 weak = translation.eigenvectors().col(0);
  result.weak_translation = weak;
  correction.head<3>() -= weak * weak.dot(correction.head<3>());
  result.T_world_base = SE3::exp(correction) * initial;
}

/// The squared radius map neighbours are searched within: the correspondence bound, at least the map's density.
float neighborhood_sq(double max_correspondence_m, const RegistrationConfig& config) {
  const double radius = std::max(max_correspondence_m, config.neighborhood_radius_m);
  return static_cast<float>(radius * radius);
}

/// The features a registration iterates over: the input as given (spans),
/// copies when they are deskewed again (MotionDeskew), or the chosen subset.
struct WorkingSet {
  std::vector<Eigen::Vector3f> edges_owned, planes_owned;
  std::vector<float> edge_times_owned, plane_times_owned;
  std::span<const Eigen::Vector3f> edges, planes;
  std::span<const float> edge_times, plane_times;  ///< with MotionDeskew only
  std::vector<PointCovariance> edge_covariances_owned, plane_covariances_owned;
  std::span<const PointCovariance> edge_covariances, plane_covariances;  ///< with QueryCovariances only
  MatchCache cache;
  /// For a subset: each feature's position among the input queries (edges, then planes); empty: the input itself.
  std::vector<std::uint32_t> positions;

  std::size_t size() const { return edges.size() + planes.size(); }
  void point_at_owned() {
    edges = edges_owned;
    planes = planes_owned;
  }
};

WorkingSet whole_input(std::span<const Eigen::Vector3f> edges, std::span<const Eigen::Vector3f> planes, const MotionDeskew* motion,
                       const QueryCovariances* covariances) {
  WorkingSet set;
  set.edges = edges;
  set.planes = planes;
  if (covariances != nullptr) {
    if (covariances->edges.size() != edges.size() || covariances->planes.size() != planes.size())
      throw std::invalid_argument("register_scan_to_map: one covariance per feature");
    set.edge_covariances = covariances->edges;
    set.plane_covariances = covariances->planes;
  }
  if (motion != nullptr) {
    set.edges_owned.assign(edges.begin(), edges.end());
    set.planes_owned.assign(planes.begin(), planes.end());
    set.point_at_owned();
    set.edge_times = motion->edge_times;
    set.plane_times = motion->plane_times;
  }
  set.cache = {std::vector<CachedMatch<MapLine>>(edges.size()), std::vector<CachedMatch<PlaneCoefficients>>(planes.size())};
  return set;
}

/// The chosen features of `all` (positions ascending, edges first), with their times and cached matches.
WorkingSet chosen_subset(const WorkingSet& all, std::span<const std::uint32_t> chosen) {
  WorkingSet set;
  const std::size_t edge_count = all.edges.size();
  const bool timed = !all.edge_times.empty() || !all.plane_times.empty();
  const bool weighted = !all.edge_covariances.empty() || !all.plane_covariances.empty();
  for (const std::uint32_t position : chosen) {
    if (position < edge_count) {
      set.edges_owned.push_back(all.edges[position]);
      set.cache.edges.push_back(all.cache.edges[position]);
      if (timed) set.edge_times_owned.push_back(all.edge_times[position]);
      if (weighted) set.edge_covariances_owned.push_back(all.edge_covariances[position]);
    } else {
      set.planes_owned.push_back(all.planes[position - edge_count]);
      set.cache.planes.push_back(all.cache.planes[position - edge_count]);
      if (timed) set.plane_times_owned.push_back(all.plane_times[position - edge_count]);
      if (weighted) set.plane_covariances_owned.push_back(all.plane_covariances[position - edge_count]);
    }
  }
  set.point_at_owned();
  set.edge_times = set.edge_times_owned;
  set.plane_times = set.plane_times_owned;
  set.edge_covariances = set.edge_covariances_owned;
  set.plane_covariances = set.plane_covariances_owned;
  set.positions.assign(chosen.begin(), chosen.end());
  return set;
}

/// What the start-pose search found for a feature.
enum class StartMatch : std::uint8_t { kUnsearched, kMatched, kUnmatched };

/// Each feature's information at the start pose, its correspondence searched
/// on first use (Algorithm 2, lines 4-10); the search fills the match cache,
/// so the first iteration does not search the chosen features again.
class LazyInformation {
 public:
  LazyInformation(const Matcher& matcher, const WorkingSet& set)
      : matcher_(matcher), set_(set), information_(set.size()), state_(set.size(), StartMatch::kUnsearched) {
    matcher_.information = information_;
  }

  const FeatureInformation* operator()(std::uint32_t i) {
    if (state_[i] == StartMatch::kUnsearched) {
      NormalEquations unused;
      information_[i].rank = 0;
      if (i < set_.edges.size())
        matcher_.edge(i, set_.edges[i], unused);
      else
        matcher_.plane(i - set_.edges.size(), set_.planes[i - set_.edges.size()], unused);
      state_[i] = information_[i].rank > 0 ? StartMatch::kMatched : StartMatch::kUnmatched;
    }
    return state_[i] == StartMatch::kMatched ? &information_[i] : nullptr;
  }

  std::vector<StartMatch> take_states() { return std::move(state_); }

 private:
  Matcher matcher_;
  const WorkingSet& set_;
  std::vector<FeatureInformation> information_;
  std::vector<StartMatch> state_;
};

/// Algorithm 2 on `set`; `start_matches` receives what the start-pose search found per feature.
SelectionReport choose_features(const Matcher& matcher, const WorkingSet& set, const SelectionConfig& config,
                                std::vector<StartMatch>& start_matches) {
  const auto start = std::chrono::steady_clock::now();
  LazyInformation information(matcher, set);
  SelectionReport report;
  report.method = config.method;
  report.budget = selection_budget(set.size(), false, config);
  // The same draws for the same input: the seed moves with the feature count.
  const std::uint64_t seed = config.seed ^ (0x9E3779B97F4A7C15ULL * (set.size() + 1));
  SelectionConfig seeded = config;
  seeded.seed = seed;
  const InformationSource source = std::ref(information);
  const SelectionResult chosen = config.method == SelectionMethod::kGreedy ? select_greedy(set.size(), report.budget, source, seeded)
                                                                           : select_random(set.size(), report.budget, source, seed);
  report.screened = chosen.visited;
  report.screened_matches = chosen.matched;
  report.log_det_selected = chosen.log_det;
  report.stopped_by_time = chosen.stopped_by_time;
  report.chosen = chosen.chosen;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  start_matches = information.take_states();
  return report;
}

/// A seeded sample of the features a selection did not choose
/// (held_out_share of the chosen count), deskewed as the chosen ones ended:
/// first those that matched at the start like the chosen, then unsearched
/// ones; never one that had no correspondence at the start.
WorkingSet held_out_sample(std::span<const Eigen::Vector3f> edges, std::span<const Eigen::Vector3f> planes, const MotionDeskew* motion,
                           const QueryCovariances* covariances, const RegistrationResult& result, std::span<const StartMatch> start,
                           const SelectionConfig& config) {
  const SelectionReport& report = *result.selection;
  std::vector<bool> chosen(result.queries, false);
  for (const std::uint32_t i : report.chosen) chosen[i] = true;
  std::vector<std::uint32_t> matched, unsearched;
  for (std::uint32_t i = 0; i < result.queries; ++i) {
    if (chosen[i]) continue;
    if (start[i] == StartMatch::kMatched) matched.push_back(i);
    if (start[i] == StartMatch::kUnsearched) unsearched.push_back(i);
  }
  const auto wanted = static_cast<std::size_t>(std::ceil(config.held_out_share * static_cast<double>(report.chosen.size())));
  std::mt19937_64 engine(config.seed ^ (0xD1B54A32D192ED03ULL * (result.queries + 1)));
  const auto draw = [&engine](std::vector<std::uint32_t>& from, std::size_t count) {  // the first `count` of `from`, drawn
    count = std::min(count, from.size());
    for (std::size_t j = 0; j < count; ++j) std::swap(from[j], from[j + engine() % (from.size() - j)]);
    from.resize(count);
  };
  draw(matched, wanted);  // 0 wanted: no check
  draw(unsearched, wanted - matched.size());
  std::vector<std::uint32_t> others = matched;
  others.insert(others.end(), unsearched.begin(), unsearched.end());
  std::sort(others.begin(), others.end());
  WorkingSet sample = chosen_subset(whole_input(edges, planes, motion, covariances), others);
  if (motion != nullptr && result.velocity_used) {
    redeskew(sample.edge_times, motion->used, *result.velocity_used, sample.edges_owned);
    redeskew(sample.plane_times, motion->used, *result.velocity_used, sample.planes_owned);
  }
  return sample;
}

/// Records the held-out features' fit and says whether it agrees with the chosen ones'.
bool held_out_agrees(const NormalEquations& fit, std::size_t sample_size, const SelectionConfig& config, RegistrationResult& result) {
  SelectionReport& report = *result.selection;
  report.held_out = sample_size;
  report.held_out_matches = fit.planes + fit.edges;
  if (sample_size == 0) return true;
  report.held_out_mean_residual_m = report.held_out_matches == 0 ? std::numeric_limits<double>::infinity()
                                                                 : fit.residual_sum / static_cast<double>(report.held_out_matches);
  // A wrong alignment leaves most of them unmatched, or matched loosely.
  return 2 * report.held_out_matches >= sample_size &&
         report.held_out_mean_residual_m <= config.held_out_residual_ratio * result.mean_residual_m + config.held_out_residual_floor_m;
}

/// The registration on every feature after a selection's fell back: the selection's report, every query chosen.
RegistrationResult with_fallback_report(RegistrationResult every_feature, SelectionReport report) {
  report.fell_back = true;
  report.chosen.resize(every_feature.queries);
  std::iota(report.chosen.begin(), report.chosen.end(), 0U);
  every_feature.selection = std::move(report);
  return every_feature;
}

/// Residuals of a subset back at their queries' positions (NaN elsewhere).
std::vector<float> residuals_at_queries(std::span<const float> subset, std::span<const std::uint32_t> positions, std::size_t queries) {
  std::vector<float> out(queries, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t i = 0; i < positions.size(); ++i) out[positions[i]] = subset[i];
  return out;
}

}  // namespace

RegistrationResult register_scan_to_map(std::span<const Eigen::Vector3f> edges_in, std::span<const Eigen::Vector3f> planes_in,
                                        const VoxelMap& edge_map, const VoxelMap& plane_map, const SE3& initial,
                                        double max_correspondence_m, const RegistrationConfig& config, const MotionDeskew* motion,
                                        const QueryCovariances* covariances) {
  // With a MotionDeskew the features are copied and deskewed again as the estimate moves.
  WorkingSet set = whole_input(edges_in, planes_in, motion, covariances);
  RegistrationResult result;
  if (motion != nullptr) result.velocity_used = motion->used;
  result.T_world_base = initial;
  result.queries = set.size();
  result.residuals_m.assign(result.queries, std::numeric_limits<float>::quiet_NaN());
  const float search_sq = neighborhood_sq(max_correspondence_m, config);
  const double rematch_sq = config.rematch_distance_m * config.rematch_distance_m;
  const double residual_sigma_sq = covariances == nullptr ? 0.0 : covariances->residual_sigma_m * covariances->residual_sigma_m;
  const auto matcher_with = [&](WorkingSet& features, std::span<float> residuals) {
    return Matcher{edge_map,
                   plane_map,
                   result.T_world_base,
                   config,
                   search_sq,
                   max_correspondence_m,
                   config.huber_delta_m,
                   rematch_sq,
                   features.cache,
                   residuals,
                   {},
                   features.edge_covariances,
                   features.plane_covariances,
                   residual_sigma_sq};
  };
  const auto matcher_for = [&](std::span<float> residuals) { return matcher_with(set, residuals); };
  // Thesis Algorithm 2 at the start pose (x_check); the iterations then see only the chosen features.
  std::vector<float> subset_residuals;
  std::vector<StartMatch> start_matches;
  std::span<float> residuals = result.residuals_m;
  if (config.selection.method != SelectionMethod::kNone && selection_budget(set.size(), false, config.selection) < set.size()) {
    result.selection = choose_features(matcher_for(residuals), set, config.selection, start_matches);
    set = chosen_subset(set, result.selection->chosen);  // the whole input stays in edges_in / planes_in
    subset_residuals.assign(set.size(), std::numeric_limits<float>::quiet_NaN());
    residuals = subset_residuals;
  }
  bool solved = true;  // false: too few matches or a singular system (no eigenvalues, no degeneracy verdict)
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    const NormalEquations eq = linearise(set.edges, set.planes, matcher_for(residuals));
    result.iterations = iteration + 1;
    result.plane_matches = eq.planes;
    result.edge_matches = eq.edges;
    result.hessian = eq.H;
    if (eq.planes + eq.edges < 6) {
      solved = false;
      break;
    }
    result.mean_residual_m = eq.residual_sum / static_cast<double>(eq.planes + eq.edges);
    const Vec6 delta = eq.H.ldlt().solve(-eq.g);
    if (!delta.allFinite()) {
      solved = false;
      break;
    }
    result.T_world_base = SE3::exp(delta) * result.T_world_base;
    if (delta.head<3>().norm() < config.convergence_translation_m && delta.tail<3>().norm() < config.convergence_rotation_rad) {
      result.converged = true;
      break;
    }
    if (motion != nullptr) {
      // Eq 4.12 again with the velocity this estimate implies.
      const BodyVelocity measured = BodyVelocity::from_relative_pose(motion->T_world_previous.inverse() * result.T_world_base, motion->dt);
      redeskew(set.edge_times, *result.velocity_used, measured, set.edges_owned);
      redeskew(set.plane_times, *result.velocity_used, measured, set.planes_owned);
      result.velocity_used = measured;
    }
  }
  if (result.selection) {
    result.residuals_m = residuals_at_queries(subset_residuals, set.positions, result.queries);
    WorkingSet sample = held_out_sample(edges_in, planes_in, motion, covariances, result, start_matches, config.selection);
    std::vector<float> sample_residuals(sample.size());
    const NormalEquations fit = linearise(sample.edges, sample.planes, matcher_with(sample, sample_residuals));
    if (!solved || !held_out_agrees(fit, sample.size(), config.selection, result)) {
      // The chosen features settled where the others do not fit: the full set decides.
      RegistrationConfig every_feature = config;
      every_feature.selection.method = SelectionMethod::kNone;
      return with_fallback_report(
          register_scan_to_map(edges_in, planes_in, edge_map, plane_map, initial, max_correspondence_m, every_feature, motion, covariances),
          std::move(*result.selection));
    }
  }
  if (!solved) return result;
  result.eigenvalues = Eigen::SelfAdjointEigenSolver<Mat6>(result.hessian).eigenvalues();
  keep_initial_along_weak_translation(initial, config.degeneracy_threshold, result);
  return result;
}

Degeneracy full_set_degeneracy(std::span<const Eigen::Vector3f> edges, std::span<const Eigen::Vector3f> planes, const VoxelMap& edge_map,
                               const VoxelMap& plane_map, const SE3& pose, double max_correspondence_m, const RegistrationConfig& config) {
  WorkingSet set = whole_input(edges, planes, nullptr, nullptr);
  std::vector<float> residuals(set.size());
  std::vector<FeatureInformation> information(set.size());
  for (FeatureInformation& f : information) f.rank = 0;
  const Matcher matcher{
      edge_map, plane_map, pose,      config,     neighborhood_sq(max_correspondence_m, config), max_correspondence_m, config.huber_delta_m,
      0.0,      set.cache, residuals, information};
  linearise(set.edges, set.planes, matcher);
  std::erase_if(information, [](const FeatureInformation& f) { return f.rank == 0; });
  return degeneracy_of(information);
}

}  // namespace mlidar::slam
