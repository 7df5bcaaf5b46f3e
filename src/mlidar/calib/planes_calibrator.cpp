#include "mlidar/calib/planes_calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mlidar/calib/planes_refine.hpp"
#include "mlidar/core/covariance.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/geometry/kabsch.hpp"

namespace mlidar::calib {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr std::size_t kMinPlanePoints = 6;
constexpr int kReassignRounds = 10;

/// At most `limit` points of plane `indices`, evenly strided (deterministic).
std::vector<Vec3> subsample(std::span<const Eigen::Vector3f> points, const std::vector<std::uint32_t>& indices, std::size_t limit) {
  const std::size_t count = std::min(limit, indices.size());
  std::vector<Vec3> out;
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k) out.push_back(points[indices[k * indices.size() / count]].cast<double>());
  return out;
}

CloudCornerReport report_of(const Corner& corner, std::size_t planes_found) {
  CloudCornerReport report;
  report.planes_found = planes_found;
  for (int i = 0; i < 3; ++i) report.planes[i] = {corner.planes[i], corner.inliers[i].size(), 0.0};
  report.angles_deg = pairwise_angles_deg(corner.planes);
  report.corner = corner.point;
  return report;
}

Plane plane_in_target(const Plane& plane_ref, const SE3& T_ref_target) {
  // n.(R q + t) + d = (R^T n).q + (n.t + d)
  return {T_ref_target.rotation().conjugate() * plane_ref.normal, plane_ref.normal.dot(T_ref_target.translation()) + plane_ref.offset};
}

void add_warnings(const PlanesConfig& config, const Corner& ref, const Corner& target, PlanesResult& result) {
  auto add = [&](PlanesWarning w) {
    if (std::find(result.warnings.begin(), result.warnings.end(), w) == result.warnings.end()) result.warnings.push_back(w);
  };
  for (const Corner* corner : {&ref, &target}) {
    if (!corner->angles_ok) add(PlanesWarning::kPlanesNearlyParallel);
    if (!corner->near_clouds) add(PlanesWarning::kCornerOutsideClouds);
    for (const auto& inliers : corner->inliers) {
      if (inliers.size() < config.warn_min_inliers) add(PlanesWarning::kFewInliers);
    }
  }
  if (result.rotation_sigma_max_deg > config.max_rotation_sigma_deg) add(PlanesWarning::kRotationPoorlyConditioned);
  if (!result.converged) add(PlanesWarning::kNotConverged);
}

}  // namespace

SE3 closed_form_T_ref_target(const std::array<Plane, 3>& ref_planes, const std::array<Plane, 3>& target_planes) {
  std::array<Vec3, 3> target_normals;
  std::array<Vec3, 3> ref_normals;
  for (int i = 0; i < 3; ++i) {
    target_normals[i] = target_planes[i].normal;
    ref_normals[i] = ref_planes[i].normal;
  }
  const Mat3 R = kabsch_rotation(target_normals, ref_normals);                // eq 2.6
  const Vec3 t = corner_point(ref_planes) - R * corner_point(target_planes);  // eq 2.7 (with R)
  return SE3(Quat(R).normalized(), t);
}

void align_order_to_guess(Corner& target, const Corner& ref, const Quat& R_ref_target) {
  int best_shift = 0;
  double best_agreement = -10.0;
  for (int shift = 0; shift < 3; ++shift) {
    double agreement = 0.0;
    for (int i = 0; i < 3; ++i) agreement += (R_ref_target * target.planes[(i + shift) % 3].normal).dot(ref.planes[i].normal);
    if (agreement > best_agreement) {
      best_agreement = agreement;
      best_shift = shift;
    }
  }
  const Corner copy = target;
  for (int i = 0; i < 3; ++i) {
    target.planes[i] = copy.planes[(i + best_shift) % 3];
    target.inliers[i] = copy.inliers[(i + best_shift) % 3];
  }
}

PlanesCalibrator::PlanesCalibrator(PlanesConfig config) : config_(std::move(config)) { config_.validate(); }

Corner PlanesCalibrator::corner_of(std::span<const Eigen::Vector3f> points, const std::string& source, std::size_t& planes_found) const {
  if (points.size() < 3 * config_.min_plane_points)
    throw InputError(
        source, "points",
        "has " + std::to_string(points.size()) + " points; three planes need at least " + std::to_string(3 * config_.min_plane_points));
  PlaneRansacConfig ransac;
  ransac.inlier_distance = config_.inlier_distance;
  ransac.max_iterations = config_.ransac_iterations;
  ransac.min_inliers = config_.min_plane_points;
  ransac.max_planes = config_.max_planes;
  ransac.seed = config_.seed;
  const std::vector<PlaneSegment> segments = extract_planes(points, ransac);  // eq 2.1-2.2
  planes_found = segments.size();
  Corner corner = find_corner(points, segments, config_, source);  // eq 2.3-2.5
  for (const auto& inliers : corner.inliers) {
    if (inliers.size() < kMinPlanePoints) throw InputError(source, "planes", "a corner plane keeps fewer than 6 points");
  }
  return corner;
}

PlanesResult PlanesCalibrator::calibrate(std::span<const Eigen::Vector3f> ref_points, std::span<const Eigen::Vector3f> target_points,
                                         const std::optional<SE3>& T_ref_target_guess, const std::string& ref_source,
                                         const std::string& target_source) const {
  std::size_t ref_found = 0;
  std::size_t target_found = 0;
  Corner ref = corner_of(ref_points, ref_source, ref_found);
  Corner target = corner_of(target_points, target_source, target_found);
  if (T_ref_target_guess) align_order_to_guess(target, ref, T_ref_target_guess->rotation());

  PlanesResult result;
  result.T_ref_target_closed_form = closed_form_T_ref_target(ref.planes, target.planes);  // eq 2.6-2.7
  const RefineOptions refine_options{config_.huber_delta, config_.max_iterations};
  auto refine = [&](const std::array<Plane, 3>& planes_ref, const SE3& T_ref_target) {
    RefineProblem problem;
    for (int i = 0; i < 3; ++i) {
      problem.ref_points[i] = subsample(ref_points, ref.inliers[i], config_.max_points_per_plane);
      problem.target_points[i] = subsample(target_points, target.inliers[i], config_.max_points_per_plane);
    }
    problem.planes_ref = planes_ref;
    problem.T_ref_target = T_ref_target;
    return refine_planes(problem, refine_options);  // eq 2.8
  };
  RefineResult refined = refine(ref.planes, result.T_ref_target_closed_form);
  // Re-collect each cloud's inliers with the refined planes until they settle,
  // so the answer does not depend on which RANSAC hypothesis won.
  for (int round = 0; round < kReassignRounds; ++round) {
    std::array<Plane, 3> target_planes;
    for (int i = 0; i < 3; ++i) target_planes[i] = plane_in_target(refined.planes_ref[i], refined.T_ref_target);
    auto ref_inliers = assign_points(ref_points, refined.planes_ref, config_.inlier_distance);
    auto target_inliers = assign_points(target_points, target_planes, config_.inlier_distance);
    if (ref_inliers == ref.inliers && target_inliers == target.inliers) break;
    for (int i = 0; i < 3; ++i) {
      if (ref_inliers[i].size() < kMinPlanePoints || target_inliers[i].size() < kMinPlanePoints)
        throw InputError(target_source, "planes", "a corner plane keeps fewer than 6 points after refinement");
    }
    ref.inliers = std::move(ref_inliers);
    target.inliers = std::move(target_inliers);
    refined = refine(refined.planes_ref, refined.T_ref_target);
  }

  result.T_ref_target = refined.T_ref_target;
  result.covariance = refined.covariance;
  result.residual_sigma = refined.residual_sigma;
  result.iterations = refined.iterations;
  result.converged = refined.converged;
  result.rotation_sigma_max_deg = largest_sd(result.covariance.bottomRightCorner<3, 3>()) / kDeg;
  result.ref = report_of(ref, ref_found);
  result.target = report_of(target, target_found);
  for (int i = 0; i < 3; ++i) {
    result.ref.planes[i].plane = refined.planes_ref[i];
    result.ref.planes[i].residual_rms = refined.rms_ref[i];
    result.target.planes[i].plane = plane_in_target(refined.planes_ref[i], refined.T_ref_target);
    result.target.planes[i].residual_rms = refined.rms_target[i];
  }
  add_warnings(config_, ref, target, result);
  return result;
}

}  // namespace mlidar::calib
