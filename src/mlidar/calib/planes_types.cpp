#include "mlidar/calib/planes_types.hpp"

#include <string>

#include "mlidar/core/error.hpp"

namespace mlidar::calib {
std::optional<PlanesConfigProblem> PlanesConfig::problem() const {
  const auto check = [](bool holds, const char* key, const char* expected) {
    return holds ? std::nullopt : std::optional<PlanesConfigProblem>({key, expected});
  };
  for (const auto& p :
       {check(inlier_distance > 0.0 && inlier_distance < 10.0, "inlier_distance", "0 < metres < 10"),
        check(ransac_iterations >= 1 && ransac_iterations <= 1000000, "ransac_iterations", "1 to 1000000"),
        check(max_planes >= 3 && max_planes <= 20, "max_planes", "3 to 20"), check(min_plane_points >= 3, "min_plane_points", "at least 3"),
        check(min_corner_angle_deg > 0.0 && min_corner_angle_deg <= 90.0, "min_corner_angle_deg", "0 < degrees <= 90"),
        check(min_any_angle_deg > 0.0 && min_any_angle_deg <= min_corner_angle_deg, "min_any_angle_deg",
              "0 < degrees <= min_corner_angle_deg"),
        check(corner_max_gap > 0.0, "corner_max_gap", "metres > 0"),
        check(max_points_per_plane >= 10, "max_points_per_plane", "at least 10"), check(huber_delta > 0.0, "huber_delta", "metres > 0"),
        check(max_iterations >= 1, "max_iterations", "at least 1"),
        check(max_rotation_sigma_deg > 0.0, "max_rotation_sigma_deg", "degrees > 0"),
        check(up.allFinite() && up.norm() > 0.5, "up", "a finite vector of length about 1")}) {
    if (p) return p;
  }
  return std::nullopt;
}

void PlanesConfig::validate() const {
  if (const auto p = problem()) throw UsageError(std::string("planes config: ") + p->key + ": expected " + p->expected);
}

const char* warning_name(PlanesWarning warning) {
  switch (warning) {
    case PlanesWarning::kPlanesNearlyParallel:
      return "planes_nearly_parallel";
    case PlanesWarning::kFewInliers:
      return "few_inliers";
    case PlanesWarning::kCornerOutsideClouds:
      return "corner_outside_clouds";
    case PlanesWarning::kRotationPoorlyConditioned:
      return "rotation_poorly_conditioned";
    case PlanesWarning::kNotConverged:
      return "not_converged";
  }
  return "unknown";
}

}  // namespace mlidar::calib
