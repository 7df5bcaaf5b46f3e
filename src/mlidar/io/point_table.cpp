#include "mlidar/io/point_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

#include "mlidar/core/error.hpp"

namespace mlidar::io {

std::size_t scalar_size(ScalarType type) {
  switch (type) {
    case ScalarType::kI8:
    case ScalarType::kU8:
      return 1;
    case ScalarType::kI16:
    case ScalarType::kU16:
      return 2;
    case ScalarType::kI32:
    case ScalarType::kU32:
    case ScalarType::kF32:
      return 4;
    case ScalarType::kI64:
    case ScalarType::kU64:
    case ScalarType::kF64:
      return 8;
  }
  return 0;
}

const char* scalar_name(ScalarType type) {
  switch (type) {
    case ScalarType::kI8:
      return "int8";
    case ScalarType::kU8:
      return "uint8";
    case ScalarType::kI16:
      return "int16";
    case ScalarType::kU16:
      return "uint16";
    case ScalarType::kI32:
      return "int32";
    case ScalarType::kU32:
      return "uint32";
    case ScalarType::kI64:
      return "int64";
    case ScalarType::kU64:
      return "uint64";
    case ScalarType::kF32:
      return "float32";
    case ScalarType::kF64:
      return "float64";
  }
  return "?";
}

bool is_float(ScalarType type) { return type == ScalarType::kF32 || type == ScalarType::kF64; }

namespace {
template <typename T>
double load(const std::byte* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

/// `read.template operator()<T>()` with T the C++ type of `type` (the one switch over the types that value and values
/// share); a value outside the enum reads nothing and gives 0.
template <typename Read>
double with_scalar_type(ScalarType type, Read&& read) {
  switch (type) {
    case ScalarType::kI8:
      return read.template operator()<std::int8_t>();
    case ScalarType::kU8:
      return read.template operator()<std::uint8_t>();
    case ScalarType::kI16:
      return read.template operator()<std::int16_t>();
    case ScalarType::kU16:
      return read.template operator()<std::uint16_t>();
    case ScalarType::kI32:
      return read.template operator()<std::int32_t>();
    case ScalarType::kU32:
      return read.template operator()<std::uint32_t>();
    case ScalarType::kI64:
      return read.template operator()<std::int64_t>();
    case ScalarType::kU64:
      return read.template operator()<std::uint64_t>();
    case ScalarType::kF32:
      return read.template operator()<float>();
    case ScalarType::kF64:
      return read.template operator()<double>();
  }
  return 0.0;
}
}  // namespace

double FieldColumn::value(std::size_t point, std::uint32_t element) const {
  const std::byte* p = data.data() + point * stride() + element * scalar_size(type);
  return with_scalar_type(type, [p]<typename T>() { return load<T>(p); });
}

std::vector<double> FieldColumn::values(std::size_t num_points, std::uint32_t element) const {
  if (num_points > 0 && (element >= count || data.size() < num_points * stride())) {
    throw std::invalid_argument("FieldColumn::values: field " + name + " holds fewer than " + std::to_string(num_points) + " points");
  }
  std::vector<double> out(num_points);
  if (num_points == 0) return out;
  const std::byte* first = data.data() + element * scalar_size(type);
  const std::size_t step = stride();
  with_scalar_type(type, [&]<typename T>() {
    for (std::size_t i = 0; i < num_points; ++i) out[i] = load<T>(first + i * step);
    return 0.0;
  });
  return out;
}

const FieldColumn* PointTable::find(const std::string& name) const {
  for (const auto& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

FieldColumn* PointTable::find(const std::string& name) { return const_cast<FieldColumn*>(std::as_const(*this).find(name)); }

FieldColumn& PointTable::add_field(const std::string& name, ScalarType type, std::uint32_t count) {
  FieldColumn column;
  column.name = name;
  column.type = type;
  column.count = count;
  column.data.resize(num_points * column.stride());
  fields.push_back(std::move(column));
  return fields.back();
}

namespace {

const FieldColumn* find_first(const PointTable& table, const auto& names) {
  for (const char* name : names) {
    if (const FieldColumn* f = table.find(name)) return f;
  }
  return nullptr;
}

double unit_scale(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kMilliseconds:
      return 1e-3;
    case TimeUnit::kMicroseconds:
      return 1e-6;
    case TimeUnit::kNanoseconds:
      return 1e-9;
    default:
      return 1.0;
  }
}

}  // namespace

std::optional<TimeUnit> parse_time_unit(const std::string& text) {
  for (const TimeUnit unit :
       {TimeUnit::kAuto, TimeUnit::kSeconds, TimeUnit::kMilliseconds, TimeUnit::kMicroseconds, TimeUnit::kNanoseconds})
    if (text == time_unit_name(unit)) return unit;
  return std::nullopt;
}

const char* time_unit_name(TimeUnit unit) {
  switch (unit) {
    case TimeUnit::kAuto:
      return "auto";
    case TimeUnit::kSeconds:
      return "s";
    case TimeUnit::kMilliseconds:
      return "ms";
    case TimeUnit::kMicroseconds:
      return "us";
    case TimeUnit::kNanoseconds:
      return "ns";
  }
  return "?";
}

const FieldColumn* find_time_field(const PointTable& table) { return find_first(table, kTimeFieldNames); }

TimeUnit time_unit_of(const FieldColumn& field, TimeUnit requested, const std::string& source) {
  if (requested != TimeUnit::kAuto) return requested;
  if (is_float(field.type)) return TimeUnit::kSeconds;
  if (scalar_size(field.type) >= 4) return TimeUnit::kNanoseconds;
  throw InputError(source, "field " + field.name,
                   std::string("is ") + scalar_name(field.type) +
                       ", which cannot hold a per-point time (expected float seconds or 32/64-bit integer nanoseconds; "
                       "set the LiDAR's time_unit in dataset.yaml if the unit differs)");
}

Scan to_scan(const PointTable& table, const std::string& source, const ScanOptions& options) {
  const FieldColumn* fx = table.find("x");
  const FieldColumn* fy = table.find("y");
  const FieldColumn* fz = table.find("z");
  for (const auto& [column, name] : {std::pair{fx, "x"}, std::pair{fy, "y"}, std::pair{fz, "z"}}) {
    if (column == nullptr) throw InputError(source, std::string("field ") + name, "missing (a point cloud needs fields x, y and z)");
  }
  const FieldColumn* fi = find_first(table, kIntensityFieldNames);
  const FieldColumn* fr = find_first(table, kRingFieldNames);
  const FieldColumn* ft = options.read_time ? find_time_field(table) : nullptr;
  const double scale = ft != nullptr ? unit_scale(time_unit_of(*ft, options.time_unit, source)) : 1.0;

  const std::size_t n = table.num_points;
  const std::vector<double> xs = fx->values(n), ys = fy->values(n), zs = fz->values(n);
  const std::vector<double> intensities = fi != nullptr ? fi->values(n) : std::vector<double>{};
  const std::vector<double> rings = fr != nullptr ? fr->values(n) : std::vector<double>{};
  const std::vector<double> times = ft != nullptr ? ft->values(n) : std::vector<double>{};
  Scan scan;
  scan.points.reserve(n);
  scan.intensity.reserve(intensities.size());
  scan.ring.reserve(rings.size());
  std::vector<double> raw_time;
  raw_time.reserve(times.size());
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p(xs[i], ys[i], zs[i]);
    if (!p.allFinite() && options.drop_nan) continue;
    scan.points.push_back(p.cast<float>());
    if (fi != nullptr) scan.intensity.push_back(static_cast<float>(intensities[i]));
    if (fr != nullptr) scan.ring.push_back(static_cast<std::uint16_t>(rings[i]));
    if (ft != nullptr) raw_time.push_back(times[i]);
  }
  if (!raw_time.empty()) {
    const auto [lo, hi] = std::minmax_element(raw_time.begin(), raw_time.end());
    if (!std::isfinite(*lo) || !std::isfinite(*hi) ||
        std::any_of(raw_time.begin(), raw_time.end(), [](double t) { return std::isnan(t); })) {
      throw InputError(source, "field " + ft->name, "holds non-finite times (NaN or infinite)");
    }
    const double start = *lo;
    scan.stamp = start * scale;
    scan.time.reserve(raw_time.size());
    for (double t : raw_time) scan.time.push_back(static_cast<float>((t - start) * scale));
  }
  return scan;
}

void add_f32_field(PointTable& table, const std::string& name, std::span<const float> values) {
  if (values.size() != table.num_points) throw std::invalid_argument("add_f32_field: one value per point for " + name);
  FieldColumn& column = table.add_field(name, ScalarType::kF32);
  if (!values.empty()) std::memcpy(column.data.data(), values.data(), values.size() * sizeof(float));
}

PointTable from_scan(const Scan& scan) {
  PointTable table;
  table.num_points = scan.size();
  table.width = static_cast<std::uint32_t>(scan.size());
  table.height = 1;
  const std::size_t n = scan.size();
  for (int axis = 0; axis < 3; ++axis) {
    FieldColumn& column = table.add_field(std::string(1, "xyz"[axis]), ScalarType::kF32);
    auto* out = reinterpret_cast<float*>(column.data.data());
    for (std::size_t i = 0; i < n; ++i) out[i] = scan.points[i][axis];
  }
  if (scan.has_intensity()) add_f32_field(table, "intensity", scan.intensity);
  if (scan.has_ring()) {
    std::memcpy(table.add_field("ring", ScalarType::kU16).data.data(), scan.ring.data(), n * sizeof(std::uint16_t));
  }
  if (scan.has_time()) {
    auto* out = reinterpret_cast<double*>(table.add_field("t", ScalarType::kF64).data.data());
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<double>(scan.time[i]);
  }
  return table;
}

}  // namespace mlidar::io
