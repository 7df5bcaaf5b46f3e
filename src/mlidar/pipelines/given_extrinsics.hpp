#pragma once
// The extrinsics a user gives a job (`--extrinsics FILE`) and the doubt each
// carries into uncertainty-aware mapping (thesis eq 4.24: alpha Xi).
#include <filesystem>
#include <optional>
#include <string>

#include "mlidar/core/types.hpp"
#include "mlidar/io/extrinsics_io.hpp"
#include "mlidar/io/frame_source.hpp"
#include "mlidar/pipelines/slam_config.hpp"

namespace mlidar::pipelines {

/// `file` read for a folder source (dataset or clouds): relative to `base` and naming every LiDAR of the source,
/// else InputError naming the file and the field (`base`, `lidars.NAME`).
io::Extrinsics read_given_extrinsics(const std::filesystem::path& file, const io::FrameSource& source, const std::string& base);

/// The configured extrinsic prior, 1-sigma per axis squared on the diagonal, [t additive, r local] as in
/// extrinsics.yaml, before alpha (mapping.extrinsic_prior_*).
Mat6 extrinsic_prior_covariance(const SlamConfig& config);

/// Eq 4.24's alpha Xi of an extrinsic T_base_lidar as the odometry uses it (left perturbation in the base frame):
/// `covariance` ([t additive, r local], the file's) or the configured prior, times window.extrinsic_covariance_scale.
Mat6 extrinsic_doubt(const std::optional<Mat6>& covariance, const SE3& T_base_lidar, const SlamConfig& config);

}  // namespace mlidar::pipelines
