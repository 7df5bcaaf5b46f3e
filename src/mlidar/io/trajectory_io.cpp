// TUM RGB-D benchmark trajectories (`t tx ty tz qx qy qz qw`) and KITTI
// odometry poses (row-major top 3x4 of T_world_base, one pose per line).
#include "mlidar/io/trajectory_io.hpp"

#include <cmath>

#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/file_bytes.hpp"
#include "mlidar/io/rigid_check.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {
namespace {

/// TUM files print quaternions with ~6 digits: norms this close to 1 are normalised.
constexpr double kQuaternionNormTolerance = 1e-3;

void check_increasing(double stamp, const Trajectory& trajectory, const std::string& source, const std::string& field) {
  if (!trajectory.empty() && !(stamp > trajectory.poses.back().stamp)) {
    throw InputError(source, field,
                     "stamp " + exact_number(stamp) + " is not after the previous pose's " + exact_number(trajectory.poses.back().stamp) +
                         " (stamps must increase)");
  }
}

StampedPose parse_tum_line(const std::vector<std::string_view>& tokens, std::size_t line, const std::string& source) {
  const std::string field = line_field(line);
  if (tokens.size() != 8) {
    throw InputError(source, field, "expected 8 values (t x y z qx qy qz qw), found " + std::to_string(tokens.size()));
  }
  double v[8];
  for (std::size_t k = 0; k < 8; ++k) v[k] = parse_finite(tokens[k], source, field);
  const Quat q(v[7], v[4], v[5], v[6]);  // Eigen's constructor takes w x y z
  const double norm = q.norm();
  if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
    throw InputError(source, field,
                     "quaternion (qx qy qz qw) has norm " + exact_number(norm) +
                         "; norms within 1e-3 of 1 are normalised, this one is too far (wrong column order or corrupt?)");
  }
  return {v[0], SE3(q, Vec3(v[1], v[2], v[3]))};
}

}  // namespace

Trajectory parse_tum(const std::string& text, const std::string& source) {
  Trajectory trajectory;
  for (const auto& line : split_lines(text)) {
    const std::string_view content = trim(line.text);
    if (content.empty() || content.front() == '#') continue;
    const StampedPose pose = parse_tum_line(split_tokens(content), line.number, source);
    check_increasing(pose.stamp, trajectory, source, line_field(line.number));
    trajectory.poses.push_back(pose);
  }
  return trajectory;
}

Trajectory read_tum(const std::filesystem::path& path) { return parse_tum(read_file_text(path), path.string()); }

void write_tum(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::string text = "# t x y z qx qy qz qw\n";
  for (const auto& pose : trajectory.poses) {
    const Vec3& t = pose.T_world_base.translation();
    const Quat& q = pose.T_world_base.rotation();
    for (double v : {pose.stamp, t.x(), t.y(), t.z(), q.x(), q.y(), q.z()}) text += exact_number(v) + " ";
    text += exact_number(q.w()) + "\n";
  }
  write_atomically(path, [&text](std::ostream& out) { out << text; });
}

Trajectory parse_kitti_poses(const std::string& text, const std::string& source, const std::vector<double>& stamps) {
  Trajectory trajectory;
  for (const auto& line : split_lines(text)) {
    const auto tokens = split_tokens(line.text);
    if (tokens.empty()) continue;
    const std::string field = line_field(line.number);
    if (tokens.size() != 12) {
      throw InputError(source, field, "expected 12 values (row-major top 3x4 of T_world_base), found " + std::to_string(tokens.size()));
    }
    Mat4 m = Mat4::Identity();
    for (int k = 0; k < 12; ++k) m(k / 4, k % 4) = parse_finite(tokens[static_cast<std::size_t>(k)], source, field);
    const std::size_t index = trajectory.size();
    if (!stamps.empty() && index >= stamps.size()) {
      throw InputError(source, field, "more poses than the " + std::to_string(stamps.size()) + " stamps given");
    }
    const double stamp = stamps.empty() ? static_cast<double>(index) : stamps[index];
    check_increasing(stamp, trajectory, source, field);
    trajectory.poses.push_back({stamp, checked_rigid(m, source, field)});
  }
  if (!stamps.empty() && trajectory.size() != stamps.size()) {
    throw InputError(
        source, "poses",
        std::to_string(trajectory.size()) + " poses but " + std::to_string(stamps.size()) + " stamps were given (one stamp per pose line)");
  }
  return trajectory;
}

Trajectory read_kitti_poses(const std::filesystem::path& path, const std::vector<double>& stamps) {
  return parse_kitti_poses(read_file_text(path), path.string(), stamps);
}

void write_kitti_poses(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::string text;
  for (const auto& pose : trajectory.poses) {
    const Mat4 m = pose.T_world_base.matrix();
    for (int k = 0; k < 12; ++k) text += exact_number(m(k / 4, k % 4)) + (k == 11 ? "\n" : " ");
  }
  write_atomically(path, [&text](std::ostream& out) { out << text; });
}

}  // namespace mlidar::io
