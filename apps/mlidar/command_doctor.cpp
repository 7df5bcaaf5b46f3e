// `mlidar doctor DATASET|BAG`: checks an input before a long run
// (pipelines/dataset_doctor.hpp) and prints each finding with its fix; exit 1
// when a job would fail on it, 0 otherwise (warnings included).
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/mlidar/bag_options.hpp"
#include "apps/mlidar/commands.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/atomic_file.hpp"
#include "mlidar/pipelines/dataset_doctor.hpp"
#include "mlidar/pipelines/frame_gaps.hpp"

namespace mlidar::cli {
namespace {

struct DoctorOptions {
  std::string input;
  BagCliOptions bag;
  std::string json_out;
};

int run_doctor(const DoctorOptions& options) {
  if (!options.json_out.empty()) io::check_output_file(options.json_out, "--json");
  const std::vector<pipelines::Finding> findings = pipelines::examine_input(options.input, options.bag);
  for (const auto& f : findings)
    std::cout << pipelines::to_string(f.severity) << "  " << f.check << (f.lidar.empty() ? "" : " " + f.lidar) << ": " << f.message << '\n';
  const bool failed = pipelines::has_failure(findings);
  std::cout << (failed ? "a run would fail: fix the failures above\n" : "no failure found\n");
  if (!options.json_out.empty()) {
    const nlohmann::json json = pipelines::doctor_json(options.input, findings);
    io::write_atomically(options.json_out, [&](std::ostream& out) { out << json.dump(2) << '\n'; });
  }
  return failed ? 1 : 0;
}

}  // namespace

Command register_doctor(CLI::App& app) {
  auto options = std::make_shared<DoctorOptions>();
  CLI::App* sub = app.add_subcommand("doctor", "Check a dataset or bag before a run: what would fail, what would mislead, and the fix");
  sub->add_option("input", options->input, "Dataset folder, or a ROS 1 / ROS 2 bag")->required()->check(CLI::ExistingPath);
  add_bag_options(*sub, options->bag, false, true);
  sub->add_option("--json", options->json_out, "Write the findings as JSON to this file");
  return {sub, [options] { return run_doctor(*options); }};
}

}  // namespace mlidar::cli
