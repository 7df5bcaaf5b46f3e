// `mlidar perturb`: a copy of a dataset with perturbed extrinsics (pipelines/perturb_dataset.hpp).
#include <iostream>
#include <memory>
#include <string>

#include "apps/mlidar/commands.hpp"
#include "apps/mlidar/progress_bar.hpp"
#include "mlidar/core/conversions.hpp"
#include "mlidar/core/so3.hpp"
#include "mlidar/io/run_folder.hpp"
#include "mlidar/pipelines/perturb_dataset.hpp"

namespace mlidar::cli {
namespace {

struct PerturbOptions {
  std::string dataset;
  pipelines::PerturbSpec spec;
  bool overwrite = false;
  std::string out;
};

int run_perturb(const PerturbOptions& options, const CliContext& context) {
  io::RunFolder run(options.out, "perturb", context.run_folder(options.overwrite, {options.dataset}));
  const auto lidars = pipelines::write_perturbed_dataset(options.dataset, options.spec, run.path(),
                                                         options.spec.fused ? terminal_progress_bar() : std::function<void(int, int)>{});
  run.commit();
  std::cout << "wrote " << options.out << ": extrinsics perturbed with alpha " << options.spec.prior.alpha << " (sigma "
            << options.spec.prior.scaled_translation_sigma() << " m, " << rad_to_deg(options.spec.prior.scaled_rotation_sigma())
            << " deg per axis, seed " << options.spec.seed << ")\n";
  for (const auto& lidar : lidars) {
    std::cout << "  " << lidar.name << ": ";
    if (!lidar.perturbed) {
      std::cout << "defines the base frame, not perturbed\n";
      continue;
    }
    const SE3 error = lidar.T_base_lidar_true.inverse() * lidar.T_base_lidar_perturbed;
    std::cout << rad_to_deg(so3_log(error.rotation()).norm()) << " deg, "
              << (lidar.T_base_lidar_perturbed.translation() - lidar.T_base_lidar_true.translation()).norm() << " m off the truth\n";
  }
  return 0;
}

}  // namespace

Command register_perturb(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<PerturbOptions>();
  CLI::App* sub = app.add_subcommand("perturb", "Copy a dataset with its extrinsics perturbed (thesis 6.6.1.3), true ones kept");
  sub->add_option("--dataset", options->dataset, "Dataset folder (or its dataset.yaml)")->required();
  sub->add_option("--alpha", options->spec.prior.alpha,
                  "Scale of eq 6.8's prior: sigma sqrt(alpha) x 0.05 m and sqrt(alpha) x 0.1 rad per axis (thesis: 0 to 0.1)")
      ->check(CLI::Range(0.0, 1.0))
      ->required();
  sub->add_option("--seed", options->spec.seed, "Random seed (same seed, same perturbation)")->capture_default_str();
  sub->add_flag("--fused", options->spec.fused,
                "Also write fused/NNNNNN.pcd: every LiDAR's points in the base frame with the field `uncertainty` = tr(Xi) (m^2)");
  sub->add_flag("--link", options->spec.link, "Hard-link the copied scans instead of copying them (same file system)");
  sub->add_option("--out", options->out, "The copy (a new or empty folder, or an earlier perturb output)")->required();
  add_overwrite_flag(*sub, options->overwrite);
  return {sub, [options, &context] { return run_perturb(*options, context); }};
}

}  // namespace mlidar::cli
