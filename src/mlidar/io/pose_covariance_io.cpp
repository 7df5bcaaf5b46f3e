#include "mlidar/io/pose_covariance_io.hpp"

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {

void write_pose_covariances(const std::filesystem::path& path, std::span<const StampedCovariance> covariances) {
  std::string text = "# stamp, upper triangle of the 6x6 covariance of T_world_base ([t additive, r local]; m^2, m rad, rad^2)\n";
  for (const StampedCovariance& c : covariances) {
    text += exact_number(c.stamp);
    for (int row = 0; row < 6; ++row)
      for (int col = row; col < 6; ++col) {
        text += ' ';
        text += exact_number(c.covariance(row, col));
      }
    text += "\n";
  }
  write_atomically(path, [&text](std::ostream& out) { out << text; });
}

std::vector<StampedCovariance> parse_pose_covariances(const std::string& text, const std::string& source) {
  std::vector<StampedCovariance> out;
  for (const auto& line : split_lines(text)) {
    const std::string_view content = trim(line.text);
    if (content.empty() || content.front() == '#') continue;
    const auto tokens = split_tokens(content);
    const std::string field = line_field(line.number);
    if (tokens.size() != 22)
      throw InputError(source, field,
                       "expected 22 values (stamp, then the 21 upper-triangle entries), found " + std::to_string(tokens.size()));
    StampedCovariance c;
    c.stamp = parse_finite(tokens[0], source, field);
    std::size_t k = 1;
    for (int row = 0; row < 6; ++row)
      for (int col = row; col < 6; ++col) c.covariance(row, col) = c.covariance(col, row) = parse_finite(tokens[k++], source, field);
    out.push_back(c);
  }
  return out;
}

std::vector<StampedCovariance> read_pose_covariances(const std::filesystem::path& path) {
  return parse_pose_covariances(read_file_text(path), path.string());
}

}  // namespace mlidar::io
