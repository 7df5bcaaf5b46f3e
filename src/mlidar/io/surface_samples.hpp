#pragma once
// A dense sampling of a scene's true surfaces (the simulator's
// groundtruth/surfaces.ply): per sample its position and unit normal, the PLY
// float fields x y z nx ny nz.
#include <filesystem>
#include <vector>

#include <Eigen/Core>

namespace mlidar::io {

struct SurfaceSamples {
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;  ///< unit, one per point
};

/// Binary PLY, written atomically. std::invalid_argument when the sizes differ.
void write_surface_samples(const std::filesystem::path& path, const SurfaceSamples& samples);

/// InputError naming the file and the field for: no samples, a missing nx/ny/nz, a non-finite value, or a normal
/// whose length is not 1 (within 1e-3).
SurfaceSamples read_surface_samples(const std::filesystem::path& path);

}  // namespace mlidar::io
