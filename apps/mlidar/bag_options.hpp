#pragma once
// The options that read a bag, shared by `bag export` and every job that
// takes --bag (odometry, slam, calibrate auto).
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "mlidar/io/bag_frames.hpp"

namespace mlidar::cli {

struct BagCliOptions {
  std::string bag;
  std::string topics;  ///< /a:top,/b:front
  std::string base;    ///< the base LiDAR (default: the first of --topics)
  std::string stamp_at = "auto";
  std::string extrinsics;  ///< YAML; default /tf_static
  std::string models;      ///< a dataset.yaml naming the LiDARs' models
  double start_s = 0.0;
  double duration_s = 0.0;  ///< 0: to the end
};

/// Adds --topics, --stamp-at, --extrinsics, --models, --start, --duration (and --bag when `with_bag`; --base when
/// `with_base`: calibrate auto has its own).
void add_bag_options(CLI::App& sub, BagCliOptions& options, bool with_bag, bool with_base);

/// The frame source's options, the files they name read.
io::BagSourceOptions bag_source_options(const BagCliOptions& options);

}  // namespace mlidar::cli
