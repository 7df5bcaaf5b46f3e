// `mlidar convert IN OUT`: between PCD, PLY and KITTI .bin, keeping every
// field the target format can hold. The output appears only when complete.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "apps/mlidar/commands.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/io/cloud_file.hpp"

namespace mlidar::cli {
namespace {

struct ConvertOptions {
  std::string input;
  std::string output;
  std::string pcd_encoding = "binary";
  bool drop_nan = false;
};

int run_convert(const ConvertOptions& options) {
  try {
    io::cloud_format_of(options.output);
  } catch (const InputError&) {
    throw UsageError("output '" + options.output + "' has no known extension (use .pcd, .ply or .bin)");
  }
  io::check_output_file(options.output, "output");
  std::error_code ec;
  if (std::filesystem::equivalent(options.input, options.output, ec))
    throw UsageError("output '" + options.output + "' is the input file; give another name (the input is never overwritten)");
  io::CloudReadOptions read_options;
  read_options.drop_nan = options.drop_nan;
  const io::CloudFile cloud = io::read_cloud(options.input, read_options);
  io::write_cloud(options.output, cloud, io::CloudWriteOptions{options.pcd_encoding});
  std::cerr << "wrote " << options.output << " (" << cloud.table.num_points << " points)\n";
  return 0;
}

}  // namespace

Command register_convert(CLI::App& app) {
  auto options = std::make_shared<ConvertOptions>();
  CLI::App* sub = app.add_subcommand("convert", "Convert a point cloud between PCD, PLY and KITTI .bin");
  sub->add_option("input", options->input, "Input file (.pcd, .ply, .bin)")->required();
  sub->add_option("output", options->output, "Output file; its extension picks the format")->required();
  sub->add_option("--encoding", options->pcd_encoding, "PCD output encoding")
      ->check(CLI::IsMember({"binary", "binary_compressed", "ascii"}));
  sub->add_flag("--drop-nan", options->drop_nan, "Drop points whose x, y or z is not finite");
  return {sub, [options] { return run_convert(*options); }};
}

}  // namespace mlidar::cli
