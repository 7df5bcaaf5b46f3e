#pragma once
// Which cloud file of a LiDAR's folder is which frame.
//
// A folder holding as many clouds (.pcd, .ply, .bin) as there are frames
// gives the k-th in natural order ("full20" before "full100") to frame k. A
// folder holding fewer must name each file by its frame number (000123.pcd is
// frame 123, as the simulator writes them); a frame without a file has no
// scan. A folder holding more clouds than frames is an error (its frames
// would be dropped silently).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace mlidar::io {

/// Digit runs compare as numbers: "full20" < "full100".
bool natural_less(const std::string& a, const std::string& b);

/// The folder's clouds in natural order; InputError when it is no folder or holds none.
std::vector<std::filesystem::path> natural_sorted_clouds(const std::filesystem::path& folder);

/// One cloud (or none) per frame by the rule above; InputError naming the
/// folder or file otherwise. `stamps_file` names the file the frame count
/// comes from in the message for too many clouds.
std::vector<std::optional<std::filesystem::path>> frame_clouds(const std::filesystem::path& folder, std::size_t frames,
                                                               const std::string& stamps_file = "times.txt");

}  // namespace mlidar::io
