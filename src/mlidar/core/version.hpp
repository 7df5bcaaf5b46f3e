#pragma once
// mlidar's version, printed by --version and recorded in every run folder's run.json.

namespace mlidar {

inline constexpr const char* kVersion = "0.1.0";

}  // namespace mlidar
