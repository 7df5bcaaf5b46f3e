#pragma once
// numpy views of mlidar's containers. A view shares the container's memory:
// the container is moved into a capsule that the arrays keep alive, so reading
// a cloud into numpy copies nothing. Arrays into mlidar are copied once (the
// containers own their storage).
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "mlidar/core/types.hpp"
#include "mlidar/io/point_table.hpp"

namespace mlidar::python {

namespace py = pybind11;

/// One array per field, in the table's order: shape (N,) or (N, count), the field's own dtype.
py::dict table_arrays(io::PointTable table);

/// A table from a mapping of field name to array (1-D, or 2-D with one row per point), every array as long
/// as "x". ValueError naming the field for a dtype mlidar cannot write or a length that differs.
io::PointTable table_from_arrays(const py::dict& arrays);

/// {"stamp", "points" (N, 3) float32, and "intensity", "ring", "time" where the scan has them}.
py::dict scan_arrays(Scan scan);

/// (N, 8) float64: stamp, tx, ty, tz, qx, qy, qz, qw (a TUM file's columns).
py::array_t<double> trajectory_array(const Trajectory& trajectory);

/// A 4x4 float64 matrix of `T`.
py::array_t<double> matrix_array(const SE3& T);

/// A copy of a fixed-size Eigen matrix as a 2-D float64 array.
template <typename Matrix>
py::array_t<double> dense_array(const Matrix& matrix) {
  py::array_t<double> out({static_cast<py::ssize_t>(matrix.rows()), static_cast<py::ssize_t>(matrix.cols())});
  auto view = out.mutable_unchecked<2>();
  for (py::ssize_t r = 0; r < matrix.rows(); ++r)
    for (py::ssize_t c = 0; c < matrix.cols(); ++c) view(r, c) = matrix(r, c);
  return out;
}

}  // namespace mlidar::python
