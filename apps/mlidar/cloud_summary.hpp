#pragma once
// What `mlidar info` reports about one point-cloud file.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "mlidar/io/cloud_file.hpp"

namespace mlidar::cli {

struct CloudSummary {
  std::string path;
  std::string format;
  std::string encoding;
  std::size_t points = 0;
  std::uint32_t width = 0;
  std::uint32_t height = 1;
  std::vector<io::FieldColumn> field_types;   ///< name, type and count only (no data)
  std::size_t nan_points = 0;                 ///< points whose x, y or z is not finite
  std::optional<Eigen::AlignedBox3d> bounds;  ///< of the finite points
  std::optional<std::string> time_field;
  double time_span_s = 0.0;
  std::optional<std::string> ring_field;
  std::size_t ring_count = 0;  ///< distinct ring values
};

CloudSummary summarize(const std::string& path, const io::CloudFile& cloud);
std::string format_text(const CloudSummary& summary);
nlohmann::json to_json(const CloudSummary& summary);

}  // namespace mlidar::cli
