// KITTI calibration files: one `NAME: v1 v2 ...` line per matrix, row-major
// (KITTI object development kit: P0..P3 3x4, R0_rect 3x3, Tr_velo_to_cam and
// Tr_imu_to_velo 3x4). Unknown names are ignored; duplicates are errors.
#include <map>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/kitti.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {
namespace {

struct CalibEntry {
  std::size_t line = 0;
  std::vector<double> values;
};

using CalibEntries = std::map<std::string, CalibEntry, std::less<>>;

CalibEntries parse_entries(const std::string& text, const std::string& source) {
  CalibEntries entries;
  for (const auto& line : split_lines(text)) {
    const std::string_view content = trim(line.text);
    if (content.empty()) continue;
    const std::size_t colon = content.find(':');
    if (colon == std::string_view::npos || colon == 0) {
      throw InputError(source, line_field(line.number), "expected 'NAME: numbers' (e.g. 'P2: 12 numbers')");
    }
    const std::string name(trim(content.substr(0, colon)));
    CalibEntry entry{line.number, {}};
    for (const auto token : split_tokens(content.substr(colon + 1))) {
      entry.values.push_back(parse_finite(token, source, line_field(line.number) + " (" + name + ")"));
    }
    if (entries.contains(name)) {
      throw InputError(source, line_field(line.number) + " (" + name + ")",
                       "appears twice (first on line " + std::to_string(entries.at(name).line) + ")");
    }
    entries.emplace(name, std::move(entry));
  }
  return entries;
}

template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> matrix_entry(const CalibEntries& entries, const std::string& name, const std::string& source) {
  const auto found = entries.find(name);
  if (found == entries.end()) throw InputError(source, name, "missing (a KITTI calib file needs P0-P3, R0_rect and Tr_velo_to_cam)");
  const auto& values = found->second.values;
  if (values.size() != static_cast<std::size_t>(Rows * Cols)) {
    throw InputError(source, line_field(found->second.line) + " (" + name + ")",
                     "expected " + std::to_string(Rows * Cols) + " numbers, found " + std::to_string(values.size()));
  }
  Eigen::Matrix<double, Rows, Cols> m;
  for (int r = 0; r < Rows; ++r) {
    for (int c = 0; c < Cols; ++c) m(r, c) = values[static_cast<std::size_t>(r * Cols + c)];
  }
  return m;
}

std::string projection_name(int index) { return std::string(1, 'P').append(std::to_string(index)); }

template <typename Matrix>
std::string calib_line(const std::string& name, const Matrix& m) {
  std::string line = name;
  line.append(1, ':');
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = 0; c < m.cols(); ++c) line.append(1, ' ').append(exact_number(m(r, c)));
  }
  return line.append(1, '\n');
}

}  // namespace

KittiCalib parse_kitti_calib(const std::string& text, const std::string& source) {
  const CalibEntries entries = parse_entries(text, source);
  KittiCalib calib;
  for (int k = 0; k < 4; ++k) calib.P[static_cast<std::size_t>(k)] = matrix_entry<3, 4>(entries, projection_name(k), source);
  calib.R0_rect = matrix_entry<3, 3>(entries, "R0_rect", source);
  calib.Tr_velo_to_cam = matrix_entry<3, 4>(entries, "Tr_velo_to_cam", source);
  if (entries.contains("Tr_imu_to_velo")) calib.Tr_imu_to_velo = matrix_entry<3, 4>(entries, "Tr_imu_to_velo", source);
  return calib;
}

KittiCalib read_kitti_calib(const std::filesystem::path& path) { return parse_kitti_calib(read_file_text(path), path.string()); }

void write_kitti_calib(const std::filesystem::path& path, const KittiCalib& calib) {
  std::string text;
  for (int k = 0; k < 4; ++k) text += calib_line(projection_name(k), calib.P[static_cast<std::size_t>(k)]);
  text += calib_line("R0_rect", calib.R0_rect);
  text += calib_line("Tr_velo_to_cam", calib.Tr_velo_to_cam);
  if (calib.Tr_imu_to_velo) text += calib_line("Tr_imu_to_velo", *calib.Tr_imu_to_velo);
  write_atomically(path, [&text](std::ostream& out) { out << text; });
}

}  // namespace mlidar::io
