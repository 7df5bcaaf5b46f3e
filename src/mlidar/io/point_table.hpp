#pragma once
// A format-neutral point cloud as read from a file: named, typed columns
// (one per field, structure of arrays) so every reader and writer can keep
// every field bit for bit. Conversion to the algorithms' Scan is explicit.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mlidar/core/types.hpp"

namespace mlidar::io {

enum class ScalarType : std::uint8_t { kI8, kU8, kI16, kU16, kI32, kU32, kI64, kU64, kF32, kF64 };

/// Bytes per scalar of this type.
std::size_t scalar_size(ScalarType type);
/// "int8", "uint16", "float32", ...
const char* scalar_name(ScalarType type);
bool is_float(ScalarType type);

/// One field: `count` scalars of `type` per point, stored point-major
/// (point i occupies bytes [i*count*size, (i+1)*count*size)). Host byte order.
struct FieldColumn {
  std::string name;
  ScalarType type = ScalarType::kF32;
  std::uint32_t count = 1;
  std::vector<std::byte> data;

  std::size_t stride() const { return scalar_size(type) * count; }
  /// Element `element` of point `point`, converted to double.
  double value(std::size_t point, std::uint32_t element = 0) const;
  /// Element `element` of every one of the first `num_points` points, converted to double as value() does (one
  /// pass with the type resolved once: what whole-cloud conversions use). std::invalid_argument when the column is
  /// shorter.
  std::vector<double> values(std::size_t num_points, std::uint32_t element = 0) const;
};

struct PointTable {
  std::size_t num_points = 0;
  std::uint32_t width = 0;  ///< organised clouds: width x height == num_points
  std::uint32_t height = 1;
  std::vector<FieldColumn> fields;

  const FieldColumn* find(const std::string& name) const;
  FieldColumn* find(const std::string& name);
  /// Appends an empty column sized for num_points and returns it.
  FieldColumn& add_field(const std::string& name, ScalarType type, std::uint32_t count = 1);
};

/// Appends a float32 column `name` holding `values` (one per point of `table`; std::invalid_argument otherwise).
void add_f32_field(PointTable& table, const std::string& name, std::span<const float> values);

/// Units of a per-point time field.
enum class TimeUnit : std::uint8_t { kAuto, kSeconds, kMilliseconds, kMicroseconds, kNanoseconds };

/// "s", "ms", "us", "ns" (and "auto"); nullopt for anything else.
std::optional<TimeUnit> parse_time_unit(const std::string& text);
const char* time_unit_name(TimeUnit unit);

struct ScanOptions {
  bool drop_nan = true;  ///< drop points whose x, y or z is not finite
  TimeUnit time_unit = TimeUnit::kAuto;
  bool read_time = true;  ///< false: ignore the time field (no Scan::time)
};

/// Names looked up for the time and ring channels, in order of preference.
inline constexpr const char* kTimeFieldNames[] = {"t", "time", "timestamp", "offset_time"};
inline constexpr const char* kRingFieldNames[] = {"ring", "laser_id"};
inline constexpr const char* kIntensityFieldNames[] = {"intensity", "reflectance", "scalar_intensity", "i"};

/// The time field of `table` (the first of kTimeFieldNames present), or null.
const FieldColumn* find_time_field(const PointTable& table);

/// The unit a time field is read in: `requested` unless kAuto, else from the
/// field's type (floating point: seconds, as Velodyne's `time` and Hesai's
/// `timestamp`; 32/64-bit integers: nanoseconds, as Ouster's `t` and Livox's
/// `offset_time`). InputError naming `source` and the field for 8/16-bit
/// integers, which cannot hold a time.
TimeUnit time_unit_of(const FieldColumn& field, TimeUnit requested, const std::string& source);

/// Builds a Scan: x y z required (InputError naming `source` otherwise),
/// intensity, ring and time mapped when present. With a time field (and
/// options.read_time), Scan::stamp is the earliest point's time in seconds as
/// the field holds it (absolute or relative; the frame source puts it on the
/// frames' clock, io/frame_source.hpp) and Scan::time[i] >= 0 counts from it;
/// without one, stamp is 0 and time empty. Non-finite times are InputError.
Scan to_scan(const PointTable& table, const std::string& source, const ScanOptions& options = {});

/// Inverse of to_scan: fields x y z (float32), intensity (float32), ring (uint16), t (float64 seconds).
PointTable from_scan(const Scan& scan);

}  // namespace mlidar::io
