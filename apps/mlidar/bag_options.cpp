#include "apps/mlidar/bag_options.hpp"

#include "mlidar/io/dataset.hpp"
#include "mlidar/io/extrinsics_io.hpp"

namespace mlidar::cli {

void add_bag_options(CLI::App& sub, BagCliOptions& options, bool with_bag, bool with_base) {
  if (with_bag) sub.add_option("--bag", options.bag, "A ROS 1 bag, an MCAP file or a rosbag2 folder instead of --dataset");
  sub.add_option("--topics", options.topics, "The bag's LiDAR topics and their names: /top/points:top,/front/points:front");
  if (with_base) sub.add_option("--base", options.base, "The base LiDAR among --topics (default: the first)");
  sub.add_option("--stamp-at", options.stamp_at,
                 "What a bag's header stamp marks when the per-point times do not say: start or end of the sweep, or auto")
      ->check(CLI::IsMember({"auto", "start", "end"}))
      ->capture_default_str();
  sub.add_option(
      "--extrinsics", options.extrinsics,
      "The LiDARs' extrinsics YAML, covariances included (default: the bag's /tf_static; odometry and slam: also instead of a dataset's)");
  sub.add_option("--models", options.models, "A dataset.yaml whose LiDARs (by name) give their models (vertical angles, ranges)");
  sub.add_option("--start", options.start_s, "Seconds after the bag's first base sweep to start at")->check(CLI::Range(0.0, 1e9));
  sub.add_option("--duration", options.duration_s, "Seconds of the bag to read (default: to the end)")->check(CLI::Range(0.0, 1e9));
}

}  // namespace mlidar::cli
