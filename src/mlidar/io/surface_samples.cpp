#include "mlidar/io/surface_samples.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "mlidar/core/error.hpp"
#include "mlidar/io/cloud_file.hpp"

namespace mlidar::io {
namespace {

constexpr const char* kNormalFields[] = {"nx", "ny", "nz"};

}  // namespace

void write_surface_samples(const std::filesystem::path& path, const SurfaceSamples& samples) {
  if (samples.points.size() != samples.normals.size()) throw std::invalid_argument("write_surface_samples: one normal per point");
  Scan scan;
  scan.points = samples.points;
  CloudFile cloud;
  cloud.format = CloudFormat::kPly;
  cloud.table = from_scan(scan);
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> values(samples.normals.size());
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = samples.normals[i][axis];
    add_f32_field(cloud.table, kNormalFields[axis], values);
  }
  write_cloud(path, cloud);
}

SurfaceSamples read_surface_samples(const std::filesystem::path& path) {
  const CloudFile cloud = read_cloud(path);
  const std::string source = path.string();
  const PointTable& table = cloud.table;
  if (table.num_points == 0) throw InputError(source, "", "holds no surface samples");
  const FieldColumn* columns[3];
  for (int axis = 0; axis < 3; ++axis)
    if ((columns[axis] = table.find(kNormalFields[axis])) == nullptr)
      throw InputError(source, kNormalFields[axis], "missing: surface samples need unit normals nx ny nz");
  const FieldColumn* xyz[3] = {table.find("x"), table.find("y"), table.find("z")};
  for (int axis = 0; axis < 3; ++axis)
    if (xyz[axis] == nullptr) throw InputError(source, std::string(1, "xyz"[axis]), "missing");
  SurfaceSamples samples;
  samples.points.reserve(table.num_points);
  samples.normals.reserve(table.num_points);
  for (std::size_t i = 0; i < table.num_points; ++i) {
    const Eigen::Vector3d p(xyz[0]->value(i), xyz[1]->value(i), xyz[2]->value(i));
    const Eigen::Vector3d n(columns[0]->value(i), columns[1]->value(i), columns[2]->value(i));
    if (!p.allFinite() || !n.allFinite()) throw InputError(source, "x y z nx ny nz", "non-finite value at sample " + std::to_string(i));
    if (std::abs(n.norm() - 1.0) > 1e-3)
      throw InputError(
          source, "nx ny nz",
          "the normal at sample " + std::to_string(i) + " has length " + std::to_string(n.norm()) + ", not 1 (write unit normals)");
    samples.points.push_back(p.cast<float>());
    samples.normals.push_back(n.cast<float>());
  }
  return samples;
}

}  // namespace mlidar::io
