#pragma once
// RUN/pose_covariance.txt: one line per frame, `stamp` then the 21 entries of
// the upper triangle (row by row: xx xy xz xrx xry xrz yy ... rzrz) of the 6x6
// covariance of T_world_base in [t, r] order, tangent [t additive (world
// frame), r local]: T = (R Exp(r), t + dt), the convention of extrinsics.yaml's
// covariance; metres^2, m rad, rad^2. '#' lines are comments.
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mlidar/core/se3.hpp"

namespace mlidar::io {

struct StampedCovariance {
  double stamp = 0.0;
  Mat6 covariance = Mat6::Zero();
};

void write_pose_covariances(const std::filesystem::path& path, std::span<const StampedCovariance> covariances);
/// Throws InputError (file, line) for a line without 22 finite numbers.
std::vector<StampedCovariance> parse_pose_covariances(const std::string& text, const std::string& source);
std::vector<StampedCovariance> read_pose_covariances(const std::filesystem::path& path);

}  // namespace mlidar::io
