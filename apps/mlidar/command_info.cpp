// `mlidar info FILE... [--json]`: what a point-cloud file holds.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "apps/mlidar/cloud_summary.hpp"
#include "apps/mlidar/commands.hpp"

namespace mlidar::cli {
namespace {

struct InfoOptions {
  std::vector<std::string> files;
  bool json = false;
};

int run_info(const InfoOptions& options) {
  nlohmann::json all = nlohmann::json::array();
  for (const auto& file : options.files) {
    const io::CloudFile cloud = io::read_cloud(file);
    const CloudSummary summary = summarize(file, cloud);
    if (options.json) {
      all.push_back(to_json(summary));
    } else {
      std::cout << format_text(summary);
    }
  }
  if (options.json) std::cout << (all.size() == 1 ? all[0] : all).dump(2) << '\n';
  return 0;
}

}  // namespace

Command register_info(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* sub = app.add_subcommand("info", "Describe point-cloud files (PCD, PLY, KITTI/nuScenes .bin)");
  sub->add_option("files", options->files, "Files to describe")->required();
  sub->add_flag("--json", options->json, "Print JSON (an object for one file, an array for several)");
  return {sub, [options] { return run_info(*options); }};
}

}  // namespace mlidar::cli
