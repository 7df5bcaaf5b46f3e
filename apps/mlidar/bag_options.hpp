#pragma once
// The options that read a bag, shared by `bag export` and every job that
// takes --bag (odometry, slam, calibrate auto).
#include <CLI/CLI.hpp>

#include "mlidar/io/bag_frames.hpp"

namespace mlidar::cli {

/// The bag options of a command (io::bag_source_options reads the files they name).
using BagCliOptions = io::BagArguments;

/// Adds --topics, --stamp-at, --extrinsics, --models, --start, --duration (and --bag when `with_bag`; --base when
/// `with_base`: calibrate auto has its own).
void add_bag_options(CLI::App& sub, BagCliOptions& options, bool with_bag, bool with_base);

}  // namespace mlidar::cli
