#pragma once
// Outputs are written to a temporary file in the destination folder and
// renamed over the target only when complete, so an interrupted or failed
// write never leaves a half file behind.
#include <filesystem>
#include <functional>
#include <ostream>

namespace mlidar::io {

/// Calls write(stream) on a temporary file next to `path`, then renames it
/// to `path`. On any failure the temporary file is removed and OutputError
/// (or the writer's exception) propagates.
void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

}  // namespace mlidar::io
