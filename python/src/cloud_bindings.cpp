// read_cloud and write_cloud: every format io/cloud_file.hpp reads, every field kept, as numpy arrays; and
// read_extrinsics, the extrinsics YAML every job reads and writes.
#include <string>

#include "array_views.hpp"
#include "bindings.hpp"
#include "mlidar/io/cloud_file.hpp"
#include "mlidar/io/extrinsics_io.hpp"

namespace mlidar::python {

void add_clouds(py::module_& module) {
  module.def(
      "read_cloud",
      [](const std::string& path, bool drop_nan, int bin_floats_per_point) {
        io::CloudReadOptions options;
        options.drop_nan = drop_nan;
        options.bin_floats_per_point = bin_floats_per_point;
        io::CloudFile cloud;
        {
          py::gil_scoped_release release;
          cloud = io::read_cloud(path, options);
        }
        return table_arrays(std::move(cloud.table));
      },
      py::arg("path"), py::arg("drop_nan") = false, py::arg("bin_floats_per_point") = 0,
      "A PCD, PLY or KITTI .bin cloud as {field name: array}, every field with its own dtype and (N,) or (N, count) "
      "shape, sharing the memory read (no copy). InputError naming the file and field for a bad one.");
  module.def(
      "write_cloud",
      [](const std::string& path, const py::dict& arrays, const std::string& pcd_encoding) {
        io::CloudFile cloud;
        cloud.format = io::cloud_format_of(path);
        cloud.table = table_from_arrays(arrays);
        io::CloudWriteOptions options;
        options.pcd_encoding = pcd_encoding;
        py::gil_scoped_release release;
        io::write_cloud(path, cloud, options);
      },
      py::arg("path"), py::arg("arrays"), py::arg("pcd_encoding") = "binary",
      "Writes {field name: array} (x, y, z and any others, one row per point) as PCD, PLY or KITTI .bin from the "
      "extension, atomically. pcd_encoding: binary, binary_compressed or ascii.");
  module.def(
      "read_extrinsics",
      [](const std::string& path) {
        io::Extrinsics extrinsics;
        {
          py::gil_scoped_release release;
          extrinsics = io::read_extrinsics(path);
        }
        py::dict lidars;
        for (const io::LidarExtrinsic& lidar : extrinsics.lidars) {
          py::dict entry;
          entry["T_base_lidar"] = matrix_array(lidar.T_base_lidar);
          entry["covariance"] = lidar.covariance ? py::object(dense_array(*lidar.covariance)) : py::object(py::none());
          lidars[py::str(lidar.name)] = entry;
        }
        py::dict out;
        out["base"] = extrinsics.base;
        out["lidars"] = lidars;
        return out;
      },
      py::arg("path"),
      "An extrinsics YAML as {'base': name, 'lidars': {name: {'T_base_lidar': 4x4, 'covariance': 6x6 in [t, r] order "
      "(m, rad) or None}}}, in file order.");
}

}  // namespace mlidar::python
