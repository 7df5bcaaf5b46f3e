#include "mlidar/pipelines/given_extrinsics.hpp"

#include "mlidar/core/conversions.hpp"
#include "mlidar/core/covariance.hpp"
#include "mlidar/core/error.hpp"

namespace mlidar::pipelines {

io::Extrinsics read_given_extrinsics(const std::filesystem::path& file, const io::FrameSource& source, const std::string& base) {
  io::Extrinsics given = io::read_extrinsics(file);
  if (given.base != base)
    throw InputError(
        file.string(), "base",
        "is '" + given.base + "' but the input's base frame is '" + base + "': give the extrinsics relative to '" + base + "'");
  for (const io::SourceLidar& lidar : source.lidars())
    if (given.find(lidar.name) == nullptr)
      throw InputError(file.string(), "lidars." + lidar.name, "missing: give every LiDAR the job reads");
  return given;
}

Mat6 extrinsic_prior_covariance(const SlamConfig& config) {
  const double t = config.mapping.extrinsic_prior_translation_m, r = deg_to_rad(config.mapping.extrinsic_prior_rotation_deg);
  Mat6 prior = Mat6::Zero();
  prior.diagonal() << t * t, t * t, t * t, r * r, r * r, r * r;
  return prior;
}

Mat6 extrinsic_doubt(const std::optional<Mat6>& covariance, const SE3& T_base_lidar, const SlamConfig& config) {
  const Mat6 local = covariance.value_or(extrinsic_prior_covariance(config));
  return covariance_in_left_tangent(T_base_lidar, config.window.extrinsic_covariance_scale * local);
}

}  // namespace mlidar::pipelines
