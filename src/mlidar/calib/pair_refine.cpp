#include "mlidar/calib/pair_refine.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/covariance.hpp"
#include "mlidar/core/fixed_decimals.hpp"

namespace mlidar::calib {
namespace {

/// One registration result with its overlap fitness.
struct Candidate {
  IcpResult icp;
  double fitness = 0.0;  ///< |S^b| / |P^b| on the fitness-thinned target
  std::string label;
};

double overlap_fitness(const KdTree3f& ref_tree, std::span<const Eigen::Vector3f> target, const SE3& T, double radius) {
  if (target.empty()) return 0.0;
  const float radius_sq = static_cast<float>(radius * radius);
  const Mat3 R = T.rotation_matrix();
  std::size_t near = 0;
  for (const Eigen::Vector3f& p : target) {
    const Vec3 mapped = R * p.cast<double>() + T.translation();
    near += ref_tree.knn(mapped.cast<float>(), 1).front().distance_sq < radius_sq ? 1 : 0;
  }
  return static_cast<double>(near) / static_cast<double>(target.size());
}

double rotation_deg_between(const SE3& a, const SE3& b) { return rad_to_deg(so3_log(a.rotation().inverse() * b.rotation()).norm()); }

/// Left-perturbation covariance of [rho, phi] to [t additive, phi]: t' = t + rho + phi x t.
Mat6 additive_translation_covariance(const Mat6& left, const Vec3& t) {
  Mat6 M = Mat6::Identity();
  M.topRightCorner<3, 3>() = -hat(t);
  const Mat6 covariance = M * left * M.transpose();
  return 0.5 * (covariance + covariance.transpose());  // exactly symmetric for the YAML writer/reader
}

/// Diagonal per-scene systematic term of the reported covariance (config, 1-sigma per axis).
Mat6 systematic_covariance(const PairRefineConfig& config) {
  const double rotation_var = std::pow(deg_to_rad(config.systematic_rotation_sd_deg), 2);
  const double translation_var = std::pow(config.systematic_translation_sd_m, 2);
  Vec6 diagonal;
  diagonal << Vec3::Constant(translation_var), Vec3::Constant(rotation_var);
  return diagonal.asDiagonal();
}

/// The checks a result must pass (empty: trusted).
std::vector<std::string> failed_checks(const Candidate& c, const PairRefineConfig& config) {
  std::vector<std::string> reasons;
  const IcpResult& icp = c.icp;
  if (!icp.enough_matches) reasons.push_back("too few matches (" + std::to_string(icp.matches) + ")");
  if (!icp.converged) reasons.push_back("ICP did not settle within " + std::to_string(config.icp.max_iterations) + " iterations");
  if (c.fitness < config.min_overlap) reasons.push_back("overlap " + fixed(c.fitness, 2) + " < " + fixed(config.min_overlap, 2));
  if (icp.rmse > config.max_rmse) reasons.push_back("rmse " + fixed(icp.rmse, 3) + " m > " + fixed(config.max_rmse, 3) + " m");
  if (icp.covariance.isZero()) {
    reasons.push_back("information matrix singular (degenerate geometry)");
  } else {
    const double rot_sd = rad_to_deg(largest_sd(icp.covariance.bottomRightCorner<3, 3>()));
    const double trans_sd = largest_sd(icp.covariance.topLeftCorner<3, 3>());
    if (rot_sd > config.max_rotation_sd_deg) reasons.push_back("rotation sd " + fixed(rot_sd, 2) + " deg too large");
    if (trans_sd > config.max_translation_sd_m) reasons.push_back("translation sd " + fixed(trans_sd, 3) + " m too large");
  }
  return reasons;
}

bool better(const Candidate& a, const Candidate& b) {
  if (a.fitness != b.fitness) return a.fitness > b.fitness;
  return a.icp.rmse < b.icp.rmse;
}

bool distinct(const SE3& a, const SE3& b, const PairRefineConfig& config) {
  return rotation_deg_between(a, b) > config.distinct_rotation_deg ||
         (a.translation() - b.translation()).norm() > config.distinct_translation_m;
}

/// A pose far from the best that fits almost as well makes the answer ambiguous.
std::vector<std::string> ambiguity(const Candidate& best, std::span<const Candidate> others, const PairRefineConfig& config) {
  std::vector<std::string> reasons;
  for (const Candidate& other : others) {
    const double rot = rotation_deg_between(best.icp.T_ref_source, other.icp.T_ref_source);
    const double trans = (best.icp.T_ref_source.translation() - other.icp.T_ref_source.translation()).norm();
    if (distinct(best.icp.T_ref_source, other.icp.T_ref_source, config) && other.fitness >= best.fitness - config.ambiguity_margin)
      reasons.push_back("ambiguous: start '" + other.label + "' reaches overlap " + fixed(other.fitness, 2) + " at " + fixed(rot, 1) +
                        " deg / " + fixed(trans, 2) + " m from the answer");
  }
  return reasons;
}

std::vector<Eigen::Vector3f> beyond(std::span<const Eigen::Vector3f> points, double min_range) {
  std::vector<Eigen::Vector3f> kept;
  const float min_sq = static_cast<float>(min_range * min_range);
  for (const Eigen::Vector3f& p : points)
    if (p.squaredNorm() >= min_sq) kept.push_back(p);
  return kept;
}

void check_config(const PairRefineConfig& config) {
  if (!(config.min_range >= 0.0) || !(config.ref_voxel_size > 0.0) || !(config.search_ref_voxel_size > 0.0) ||
      !(config.overlap_radius > 0.0) || !(config.fitness_voxel_size > 0.0))
    throw std::invalid_argument("refine_pair: voxel sizes and overlap_radius must be > 0");
  if (!(config.systematic_rotation_sd_deg >= 0.0) || !(config.systematic_translation_sd_m >= 0.0))
    throw std::invalid_argument("refine_pair: systematic sd must be >= 0");
  if (config.search_finalists == 0) throw std::invalid_argument("refine_pair: search_finalists must be >= 1");
}

/// The multi-start stage: short ICP from every start, the best few refined fully.
std::vector<Candidate> search(RefSurface& surface, std::span<const Eigen::Vector3f> ref, std::span<const Eigen::Vector3f> target,
                              std::span<const Eigen::Vector3f> fitness_target, const SE3& T_init, const PairRefineConfig& config,
                              PairRefineResult& result) {
  RefSurface coarse(voxel_downsample(ref, config.search_ref_voxel_size), config.surface);
  std::vector<Candidate> shorts;
  for (const StartPose& start : coarse_starts(ref, target, T_init, config.search)) {
    Candidate c{point_to_plane_icp(coarse, target, start.T_ref_target, config.search_icp), 0.0, start.label};
    c.fitness = overlap_fitness(coarse.tree(), fitness_target, c.icp.T_ref_source, config.overlap_radius);
    result.starts.push_back({start.label, start.T_ref_target, c.icp.T_ref_source, c.fitness, c.icp.rmse});
    shorts.push_back(std::move(c));
  }
  std::stable_sort(shorts.begin(), shorts.end(), better);
  std::vector<Candidate> finalists;
  std::vector<SE3> refined_from;
  for (const Candidate& s : shorts) {
    if (finalists.size() == config.search_finalists) break;
    const bool seen =
        std::any_of(refined_from.begin(), refined_from.end(), [&](const SE3& T) { return !distinct(T, s.icp.T_ref_source, config); });
    if (seen) continue;  // the same basin as a better start
    refined_from.push_back(s.icp.T_ref_source);
    Candidate c{point_to_plane_icp(surface, target, s.icp.T_ref_source, config.icp), 0.0, s.label};
    c.fitness = overlap_fitness(surface.tree(), fitness_target, c.icp.T_ref_source, config.overlap_radius);
    finalists.push_back(std::move(c));
  }
  return finalists;
}

/// Midpoint of T_forward and the inverse of the reverse registration on SO(3) x R^3
/// (half the geodesic from one rotation to the other; mean translation), or nullopt
/// when the reverse registration did not settle or is a distinct pose.
std::optional<SE3> symmetric_answer(std::span<const Eigen::Vector3f> ref, std::span<const Eigen::Vector3f> target, const SE3& T_forward,
                                    const PairRefineConfig& config) {
  RefSurface target_surface(std::vector<Eigen::Vector3f>(target.begin(), target.end()), config.surface);
  const IcpResult back = point_to_plane_icp(target_surface, ref, T_forward.inverse(), config.icp);
  const SE3 T_backward = back.T_ref_source.inverse();
  if (!back.converged || !back.enough_matches || distinct(T_forward, T_backward, config)) return std::nullopt;
  const Vec3 half = 0.5 * so3_log(T_backward.rotation() * T_forward.rotation().inverse());
  return SE3(so3_exp(half) * T_forward.rotation(), 0.5 * (T_forward.translation() + T_backward.translation()));
}

}  // namespace

std::string_view to_string(PairVerdict verdict) {
  switch (verdict) {
    case PairVerdict::kConverged:
      return "converged";
    case PairVerdict::kSearchedAndConverged:
      return "searched_and_converged";
    case PairVerdict::kNotConverged:
      return "not_converged";
  }
  return "not_converged";
}

PairRefineResult refine_pair(std::span<const Eigen::Vector3f> ref, std::span<const Eigen::Vector3f> target, const SE3& T_init,
                             const PairRefineConfig& config) {
  check_config(config);
  PairRefineResult result;
  result.T_init = T_init;
  result.T_ref_target = T_init;
  const std::vector<Eigen::Vector3f> ref_thin = voxel_downsample(beyond(ref, config.min_range), config.ref_voxel_size);
  const std::vector<Eigen::Vector3f> target_far = beyond(target, config.min_range);
  const std::vector<Eigen::Vector3f> target_thin = voxel_downsample(target_far, config.ref_voxel_size);
  const std::vector<Eigen::Vector3f> fitness_target = voxel_downsample(target_far, config.fitness_voxel_size);
  if (ref_thin.size() < config.surface.normal_neighbours || target_thin.empty()) {
    result.reasons.push_back("a cloud has too few finite points");
    return result;
  }
  RefSurface surface(ref_thin, config.surface);

  // 1. Point-to-plane ICP from the guess.
  Candidate from_init{point_to_plane_icp(surface, target_thin, T_init, config.icp), 0.0, "init"};
  from_init.fitness = overlap_fitness(surface.tree(), fitness_target, from_init.icp.T_ref_source, config.overlap_radius);
  std::vector<Candidate> candidates{from_init};

  // 2. Multi-start search when the registration from the guess is poor, or when asked.
  const bool poor = !failed_checks(from_init, config).empty();
  result.searched = config.search_mode == PairSearchMode::kAlways || (config.search_mode == PairSearchMode::kAuto && poor);
  if (result.searched) {
    for (Candidate& c : search(surface, ref_thin, target_thin, fitness_target, T_init, config, result)) candidates.push_back(std::move(c));
  }
  std::stable_sort(candidates.begin(), candidates.end(), better);
  const Candidate& best = candidates.front();

  // 3. The answer (symmetric: the midpoint of both directions), its uncertainty and overlap (eq 3.13-3.14), and the verdict.
  result.T_ref_target = best.icp.T_ref_source;
  if (config.symmetric) {
    if (const std::optional<SE3> T = symmetric_answer(ref_thin, target_thin, result.T_ref_target, config)) {
      result.T_ref_target = *T;
      result.symmetric = true;
    }
  }
  result.chosen_start = best.label;
  result.information = best.icp.information;
  result.covariance_icp = additive_translation_covariance(best.icp.covariance, result.T_ref_target.translation());
  result.covariance = result.covariance_icp + systematic_covariance(config);
  result.rotation_sd_deg = rad_to_deg(largest_sd(result.covariance.bottomRightCorner<3, 3>()));
  result.translation_sd_m = largest_sd(result.covariance.topLeftCorner<3, 3>());
  result.rmse = best.icp.rmse;
  result.inlier_ratio = best.icp.inlier_ratio;
  result.iterations = best.icp.iterations;
  result.overlap = overlap(surface.tree(), target_thin, result.T_ref_target, config.overlap_radius);
  result.reasons = failed_checks(best, config);
  for (std::string& reason : ambiguity(best, std::span(candidates).subspan(1), config)) result.reasons.push_back(std::move(reason));
  if (result.reasons.empty()) result.verdict = best.label == "init" ? PairVerdict::kConverged : PairVerdict::kSearchedAndConverged;
  return result;
}

}  // namespace mlidar::calib
