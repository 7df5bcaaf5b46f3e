#include "array_views.hpp"

#include <cstring>
#include <memory>
#include <utility>

namespace mlidar::python {
namespace {

py::dtype dtype_of(io::ScalarType type) {
  switch (type) {
    case io::ScalarType::kI8:
      return py::dtype::of<std::int8_t>();
    case io::ScalarType::kU8:
      return py::dtype::of<std::uint8_t>();
    case io::ScalarType::kI16:
      return py::dtype::of<std::int16_t>();
    case io::ScalarType::kU16:
      return py::dtype::of<std::uint16_t>();
    case io::ScalarType::kI32:
      return py::dtype::of<std::int32_t>();
    case io::ScalarType::kU32:
      return py::dtype::of<std::uint32_t>();
    case io::ScalarType::kI64:
      return py::dtype::of<std::int64_t>();
    case io::ScalarType::kU64:
      return py::dtype::of<std::uint64_t>();
    case io::ScalarType::kF32:
      return py::dtype::of<float>();
    case io::ScalarType::kF64:
      return py::dtype::of<double>();
  }
  return py::dtype::of<float>();
}

/// The ScalarType of a numpy dtype, by kind and size; false for one mlidar's formats cannot hold.
bool scalar_type_of(const py::dtype& dtype, io::ScalarType& type) {
  const char kind = dtype.kind();
  const auto size = dtype.itemsize();
  struct Entry {
    char kind;
    py::ssize_t size;
    io::ScalarType type;
  };
  static constexpr Entry kTypes[] = {
      {'i', 1, io::ScalarType::kI8},  {'u', 1, io::ScalarType::kU8},  {'i', 2, io::ScalarType::kI16}, {'u', 2, io::ScalarType::kU16},
      {'i', 4, io::ScalarType::kI32}, {'u', 4, io::ScalarType::kU32}, {'i', 8, io::ScalarType::kI64}, {'u', 8, io::ScalarType::kU64},
      {'f', 4, io::ScalarType::kF32}, {'f', 8, io::ScalarType::kF64},
  };
  for (const Entry& entry : kTypes) {
    if (entry.kind == kind && entry.size == size) {
      type = entry.type;
      return true;
    }
  }
  return false;
}

/// An array over `data` (`rows` x `columns` of `dtype`) that keeps `owner` alive.
py::array view(const py::dtype& dtype, std::size_t rows, std::size_t columns, const void* data, const py::capsule& owner) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)};
  if (columns != 1) shape.push_back(static_cast<py::ssize_t>(columns));
  return py::array(dtype, shape, {}, data, owner);
}

template <typename T>
py::capsule owning_capsule(T value) {
  auto* held = new T(std::move(value));
  return py::capsule(held, [](void* p) { delete static_cast<T*>(p); });
}

}  // namespace

py::dict table_arrays(io::PointTable table) {
  const std::size_t points = table.num_points;
  const py::capsule owner = owning_capsule(std::move(table));
  const auto* held = static_cast<const io::PointTable*>(owner.get_pointer());
  py::dict arrays;
  for (const io::FieldColumn& column : held->fields)
    arrays[py::str(column.name)] = view(dtype_of(column.type), points, column.count, column.data.data(), owner);
  return arrays;
}

io::PointTable table_from_arrays(const py::dict& arrays) {
  io::PointTable table;
  if (!arrays.contains("x")) throw py::value_error("write_cloud: the arrays have no field 'x' (x, y and z are needed)");
  table.num_points = static_cast<std::size_t>(py::len(arrays["x"]));
  table.width = static_cast<std::uint32_t>(table.num_points);
  for (const auto& [key, value] : arrays) {
    const std::string name = py::str(key);
    const auto array = py::array::ensure(value, py::array::c_style);
    io::ScalarType type{};
    if (!array || !scalar_type_of(array.dtype(), type))
      throw py::value_error("write_cloud: field '" + name + "' is no array of int8-64, uint8-64, float32 or float64");
    if (array.ndim() < 1 || array.ndim() > 2 || static_cast<std::size_t>(array.shape(0)) != table.num_points)
      throw py::value_error("write_cloud: field '" + name + "' must be 1-D or 2-D with " + std::to_string(table.num_points) +
                            " rows, as 'x'");
    const auto count = static_cast<std::uint32_t>(array.ndim() == 2 ? array.shape(1) : 1);
    io::FieldColumn& column = table.add_field(name, type, count);
    if (!column.data.empty()) std::memcpy(column.data.data(), array.data(), column.data.size());
  }
  return table;
}

py::dict scan_arrays(Scan scan) {
  const std::size_t points = scan.size();
  const py::capsule owner = owning_capsule(std::move(scan));
  const auto* held = static_cast<const Scan*>(owner.get_pointer());
  py::dict arrays;
  arrays["stamp"] = held->stamp;
  arrays["points"] = view(py::dtype::of<float>(), points, 3, held->points.data(), owner);
  if (held->has_intensity()) arrays["intensity"] = view(py::dtype::of<float>(), points, 1, held->intensity.data(), owner);
  if (held->has_ring()) arrays["ring"] = view(py::dtype::of<std::uint16_t>(), points, 1, held->ring.data(), owner);
  if (held->has_time()) arrays["time"] = view(py::dtype::of<float>(), points, 1, held->time.data(), owner);
  return arrays;
}

py::array_t<double> trajectory_array(const Trajectory& trajectory) {
  py::array_t<double> out({static_cast<py::ssize_t>(trajectory.size()), py::ssize_t{8}});
  auto rows = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const StampedPose& pose = trajectory.poses[i];
    const Vec3& t = pose.T_world_base.translation();
    const Quat& q = pose.T_world_base.rotation();
    const double values[8] = {pose.stamp, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
    for (py::ssize_t c = 0; c < 8; ++c) rows(static_cast<py::ssize_t>(i), c) = values[c];
  }
  return out;
}

py::array_t<double> matrix_array(const SE3& T) { return dense_array(T.matrix()); }

}  // namespace mlidar::python
