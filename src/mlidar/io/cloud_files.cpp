#include "mlidar/io/cloud_files.hpp"

#include <algorithm>
#include <cctype>
#include <string_view>

#include "mlidar/core/error.hpp"
#include "mlidar/io/text_fields.hpp"

namespace mlidar::io {
namespace {

bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

std::string_view digit_run(const std::string& text, std::size_t& i) {
  const std::size_t begin = i;
  while (i < text.size() && is_digit(text[i])) ++i;
  std::string_view run(text.data() + begin, i - begin);
  while (run.size() > 1 && run.front() == '0') run.remove_prefix(1);
  return run;
}

/// The frame number a file stem names (digits only), or nullopt.
std::optional<std::size_t> frame_number(const std::string& stem) {
  const bool digits = !stem.empty() && stem.size() <= 9 && std::all_of(stem.begin(), stem.end(), is_digit);
  if (!digits) return std::nullopt;
  return static_cast<std::size_t>(std::stoul(stem));
}

}  // namespace

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      const std::string_view da = digit_run(a, i);
      const std::string_view db = digit_run(b, j);
      if (da.size() != db.size()) return da.size() < db.size();
      if (da != db) return da < db;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

std::vector<std::filesystem::path> natural_sorted_clouds(const std::filesystem::path& folder) {
  if (!std::filesystem::is_directory(folder)) throw InputError(folder.string(), "folder", "is not a folder of point clouds");
  std::vector<std::filesystem::path> clouds;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    const std::string ext = lowercase(entry.path().extension().string());
    if (ext == ".pcd" || ext == ".ply" || ext == ".bin") clouds.push_back(entry.path());
  }
  std::sort(clouds.begin(), clouds.end(),
            [](const auto& a, const auto& b) { return natural_less(a.filename().string(), b.filename().string()); });
  if (clouds.empty()) throw InputError(folder.string(), "folder", "holds no .pcd, .ply or .bin clouds");
  return clouds;
}

std::vector<std::optional<std::filesystem::path>> frame_clouds(const std::filesystem::path& folder, std::size_t frames,
                                                               const std::string& stamps_file) {
  const std::vector<std::filesystem::path> clouds = natural_sorted_clouds(folder);
  const std::string counts = std::to_string(clouds.size()) + " clouds for " + std::to_string(frames) + " stamps";
  if (clouds.size() > frames)
    throw InputError(folder.string(), "clouds", "has " + counts + " in " + stamps_file + " (give one stamp per frame)");
  std::vector<std::optional<std::filesystem::path>> by_frame(frames);
  if (clouds.size() == frames) {
    std::copy(clouds.begin(), clouds.end(), by_frame.begin());
    return by_frame;
  }
  for (const auto& cloud : clouds) {
    const std::optional<std::size_t> k = frame_number(cloud.stem().string());
    if (!k || *k >= frames)
      throw InputError(cloud.string(), "file name",
                       "has " + counts + " in " + stamps_file + ": with scans missing, each file must be named by its frame number (0 to " +
                           std::to_string(frames - 1) + "), e.g. 000123.pcd");
    if (by_frame[*k])
      throw InputError(cloud.string(), "file name", "names frame " + std::to_string(*k) + " like " + by_frame[*k]->string());
    by_frame[*k] = cloud;
  }
  return by_frame;
}

}  // namespace mlidar::io
