// 4x4 matrix files: BALM pose CSVs (stamp in the bottom-right element) and
// single homogeneous transforms (scan_pair T_target_source.txt).
#include <cmath>
#include <limits>

#include "mlidar/core/error.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/rigid_check.hpp"
#include "mlidar/io/text_fields.hpp"
#include "mlidar/io/trajectory_io.hpp"

namespace mlidar::io {

SE3 checked_rigid(const Mat4& matrix, const std::string& source, const std::string& field, double tolerance) {
  const Mat3 r = matrix.topLeftCorner<3, 3>();
  const double error = (r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(error <= tolerance) || r.determinant() <= 0.0) {
    throw InputError(source, field,
                     "rotation block is not a rotation (max |R^T R - I| = " + exact_number(error) + ", det = " +
                         exact_number(r.determinant()) + "; expected within " + exact_number(tolerance) + " of orthonormal with det +1)");
  }
  // Orthonormality was checked above against this reader's tolerance; only project here.
  return SE3::from_matrix(matrix, std::numeric_limits<double>::infinity());
}

namespace {

void check_bottom_row(const Eigen::RowVector4d& row, bool last_is_stamp, const std::string& source, const std::string& field) {
  const bool ok = row.head<3>().isZero(1e-9) && (last_is_stamp || std::abs(row(3) - 1.0) <= 1e-9);
  if (!ok) {
    throw InputError(source, field, std::string("bottom row must be 0 0 0 ") + (last_is_stamp ? "<stamp>" : "1"));
  }
}

}  // namespace

Trajectory parse_balm_poses(const std::string& text, const std::string& source) {
  std::vector<std::pair<std::size_t, std::vector<std::string_view>>> rows;
  for (const auto& line : split_lines(text)) {
    auto tokens = split_tokens(line.text, ',');
    if (tokens.empty()) continue;
    if (tokens.size() != 4) {
      throw InputError(source, line_field(line.number), "expected 4 comma-separated values, found " + std::to_string(tokens.size()));
    }
    rows.emplace_back(line.number, std::move(tokens));
  }
  if (rows.size() % 4 != 0) {
    throw InputError(source, "rows", std::to_string(rows.size()) + " matrix rows is not a multiple of 4 (file truncated?)");
  }
  Trajectory trajectory;
  for (std::size_t first = 0; first < rows.size(); first += 4) {
    Mat4 m;
    for (int r = 0; r < 4; ++r) {
      const auto& [number, tokens] = rows[first + static_cast<std::size_t>(r)];
      for (int c = 0; c < 4; ++c) m(r, c) = parse_finite(tokens[static_cast<std::size_t>(c)], source, line_field(number));
    }
    const std::string field = line_field(rows[first].first) + "-" + std::to_string(rows[first + 3].first);
    check_bottom_row(m.row(3), true, source, field);
    const double stamp = m(3, 3);
    if (!trajectory.empty() && !(stamp > trajectory.poses.back().stamp)) {
      throw InputError(source, field, "stamp " + exact_number(stamp) + " is not after the previous pose's (stamps must increase)");
    }
    m(3, 3) = 1.0;
    trajectory.poses.push_back({stamp, checked_rigid(m, source, field)});
  }
  return trajectory;
}

Trajectory read_balm_poses(const std::filesystem::path& path) { return parse_balm_poses(read_file_text(path), path.string()); }

SE3 parse_matrix_transform(const std::string& text, const std::string& source) {
  const auto tokens = split_tokens(text);
  if (tokens.size() != 16) {
    throw InputError(source, "matrix", "expected 16 numbers (a row-major 4x4 matrix), found " + std::to_string(tokens.size()));
  }
  Mat4 m;
  for (int k = 0; k < 16; ++k) {
    m(k / 4, k % 4) = parse_finite(tokens[static_cast<std::size_t>(k)], source, "matrix element " + std::to_string(k + 1));
  }
  check_bottom_row(m.row(3), false, source, "matrix");
  return checked_rigid(m, source, "matrix");
}

SE3 read_matrix_transform(const std::filesystem::path& path) { return parse_matrix_transform(read_file_text(path), path.string()); }

}  // namespace mlidar::io
