#pragma once
// The progress bar long jobs show: on stderr, only when stderr is a terminal
// (scripts and CI logs stay quiet).
#include <functional>

namespace mlidar::cli {

/// Returns a callback (done, total) drawing "[####    ] done/total frames",
/// or an empty function when stderr is not a terminal.
std::function<void(int, int)> terminal_progress_bar();

}  // namespace mlidar::cli
