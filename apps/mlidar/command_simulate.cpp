// `mlidar simulate drive|corner|detection`: the built-in simulator with ground truth.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "apps/mlidar/commands.hpp"
#include "apps/mlidar/progress_bar.hpp"
#include "mlidar/core/error.hpp"
#include "mlidar/io/pcd.hpp"
#include "mlidar/io/run_folder.hpp"
#include "mlidar/io/trajectory_io.hpp"
#include "mlidar/sim/corner_dataset.hpp"
#include "mlidar/sim/detection_dataset.hpp"
#include "mlidar/sim/drive_dataset.hpp"

namespace mlidar::cli {
namespace {

struct DriveOptions {
  std::string rig = "rv";
  std::string scene = "campus";
  std::string trajectory = "vehicle";
  int frames = 100;
  std::uint64_t seed = 1;
  std::string perturb = "0,0";
  std::string encoding = "binary";
  double surfaces = 0.0;
  bool overwrite = false;
  std::string out;
};

struct DetectionOptions {
  std::string rig = "lyft";
  int frames = 100;
  std::uint64_t seed = 1;
  std::string split = "train";
  std::string scene = "street";
  std::string encoding = "binary";
  bool overwrite = false;
  std::string out;
};

struct CornerOptions {
  sim::CornerSpec spec;
  std::string angles = "60:120";
  bool overwrite = false;
  std::string out;
};

/// "A,B" or "A:B[:C]" into numbers; UsageError naming the option otherwise.
std::vector<double> split_numbers(const std::string& text, char separator, const std::string& option) {
  std::vector<double> values;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find(separator, begin), text.size());
    try {
      std::size_t used = 0;
      const std::string part = text.substr(begin, end - begin);
      values.push_back(std::stod(part, &used));
      if (used != part.size() || !std::isfinite(values.back())) throw std::invalid_argument(part);
    } catch (const std::exception&) {
      throw UsageError(option + " '" + text + "': expected finite numbers separated by '" + separator + "'");
    }
    begin = end + 1;
  }
  return values;
}

sim::SimTrajectory load_trajectory(const std::string& name, double base_height) {
  for (const auto& known : sim::trajectory_names()) {
    if (name == known) return sim::SimTrajectory::named(name, base_height);
  }
  if (!std::filesystem::is_regular_file(name)) return sim::SimTrajectory::named(name, base_height);  // UsageError
  return sim::SimTrajectory::through(io::read_tum(name));
}

int run_drive(const DriveOptions& options, const CliContext& context) {
  const auto perturb = split_numbers(options.perturb, ',', "--perturb");
  if (perturb.size() != 2 || perturb[0] < 0.0 || perturb[0] > 180.0 || perturb[1] < 0.0 || perturb[1] > 100.0)
    throw UsageError("--perturb '" + options.perturb + "': expected DEG,M (degrees in [0, 180], metres in [0, 100])");
  io::RunFolder run(options.out, "simulate drive", context.run_folder(options.overwrite, {}));
  sim::DriveSpec spec;
  spec.rig = sim::load_rig(options.rig);
  spec.scene = options.scene;
  spec.trajectory = load_trajectory(options.trajectory, spec.rig.base_height);
  spec.frames = options.frames;
  spec.seed = options.seed;
  spec.perturb_deg = perturb[0];
  spec.perturb_m = perturb[1];
  spec.encoding = io::pcd_encoding_from_name(options.encoding);
  spec.surface_spacing_m = options.surfaces;
  sim::write_drive_dataset(spec, run.path(), terminal_progress_bar());
  run.commit();
  std::cout << "wrote " << options.out << ": " << spec.frames << " frames of " << spec.rig.lidars.size() << " LiDAR(s), rig "
            << spec.rig.name << ", scene " << spec.scene << ", trajectory " << options.trajectory << '\n';
  return 0;
}

int run_corner(CornerOptions& options, const CliContext& context) {
  const auto angles = split_numbers(options.angles, ':', "--angles");
  if (angles.size() < 2 || angles.size() > 3) throw UsageError("--angles expects A:B or A:B:STEP (degrees)");
  options.spec.angle_min = angles[0];
  options.spec.angle_max = angles[1];
  if (angles.size() == 3) options.spec.angle_step = angles[2];
  io::RunFolder run(options.out, "simulate corner", context.run_folder(options.overwrite, {}));
  sim::write_corner_dataset(options.spec, run.path());
  run.commit();
  std::cout << "wrote " << options.out << ": two-LiDAR wall-corner clouds (thesis Table 2.2 protocol)\n";
  return 0;
}

int run_detection(const DetectionOptions& options, const CliContext& context) {
  sim::DetectionSpec spec;
  spec.rig = sim::load_rig(options.rig);
  spec.frames = options.frames;
  spec.seed = options.seed;
  spec.split = sim::detection_split_from_name(options.split);
  spec.layout = sim::detection_layout_from_name(options.scene);
  spec.encoding = io::pcd_encoding_from_name(options.encoding);
  io::RunFolder run(options.out, "simulate detection", context.run_folder(options.overwrite, {}));
  sim::write_detection_dataset(spec, run.path(), terminal_progress_bar());
  run.commit();
  std::cout << "wrote " << options.out << ": " << spec.frames << " labelled " << options.split << " scenes of " << spec.rig.lidars.size()
            << " LiDAR(s), rig " << spec.rig.name << " (labels in groundtruth/label_2 and groundtruth/labels)\n";
  return 0;
}

void add_detection(CLI::App& simulate, DetectionOptions& options) {
  CLI::App* cmd = simulate.add_subcommand("detection", "Labelled street scenes for 3D detection: cars, pedestrians, cyclists");
  cmd->add_option("--rig", options.rig, "lyft (TOP, FRONT_LEFT, FRONT_RIGHT), another named rig, or a rig .yaml")->capture_default_str();
  cmd->add_option("--frames", options.frames, "Number of scenes (one frame each)")->check(CLI::Range(1, 1000000))->capture_default_str();
  cmd->add_option("--seed", options.seed, "Random seed (same seed and split, same bytes)")->capture_default_str();
  cmd->add_option("--split", options.split, "train or test: the two never share a scene")
      ->check(CLI::IsMember({"train", "test"}))
      ->capture_default_str();
  cmd->add_option("--scene", options.scene, "street (streets with clutter, cars, pedestrians, cyclists) or cars (a few cars on open "
                                            "ground, nothing else: quick tests)")
      ->check(CLI::IsMember({"street", "cars"}))
      ->capture_default_str();
  cmd->add_option("--encoding", options.encoding, "PCD encoding of the scans")
      ->check(CLI::IsMember({"binary", "binary_compressed"}))
      ->capture_default_str();
  cmd->add_option("--out", options.out, "Dataset folder (a new or empty folder, or an earlier simulate output)")->required();
  add_overwrite_flag(*cmd, options.overwrite);
}

}  // namespace

Command register_simulate(CLI::App& app, const CliContext& context) {
  CLI::App* sub = app.add_subcommand("simulate", "Simulate a multi-LiDAR dataset with ground truth");
  sub->require_subcommand(1);

  auto drive = std::make_shared<DriveOptions>();
  CLI::App* drive_cmd = sub->add_subcommand("drive", "A rig moving through a scene: scans, trajectory, extrinsics, boxes");
  drive_cmd->add_option("--rig", drive->rig, "rhd, rv, lyft, single-vlp16, single-hdl64, or a rig .yaml")->capture_default_str();
  drive_cmd->add_option("--scene", drive->scene, "corner, room, corridor, campus, street")->capture_default_str();
  drive_cmd->add_option("--trajectory", drive->trajectory, "handheld, vehicle, corridor, static, or a TUM file")->capture_default_str();
  drive_cmd->add_option("--frames", drive->frames, "Number of frames")->check(CLI::Range(1, 1000000))->capture_default_str();
  drive_cmd->add_option("--seed", drive->seed, "Random seed (same seed, same bytes)")->capture_default_str();
  drive_cmd->add_option("--perturb", drive->perturb, "Perturb the initial extrinsics: DEG,M")->capture_default_str();
  drive_cmd->add_option("--encoding", drive->encoding, "PCD encoding of the scans (binary_compressed: about a third smaller)")
      ->check(CLI::IsMember({"binary", "binary_compressed"}))
      ->capture_default_str();
  drive_cmd
      ->add_option("--surfaces", drive->surfaces,
                   "Also write groundtruth/surfaces.ply: the scenery's exact hits, one per cube of this edge (m, e.g. 0.1), with normals, "
                   "for `eval map --gt-surfaces`")
      ->check(CLI::Range(0.01, 10.0));
  drive_cmd->add_option("--out", drive->out, "Dataset folder (a new or empty folder, or an earlier simulate output)")->required();
  add_overwrite_flag(*drive_cmd, drive->overwrite);

  auto corner = std::make_shared<CornerOptions>();
  CLI::App* corner_cmd = sub->add_subcommand("corner", "Thesis Table 2.2 protocol: two clouds of three planes");
  corner_cmd->add_option("--out", corner->out, "Output folder (a new or empty folder, or an earlier simulate output)")->required();
  add_overwrite_flag(*corner_cmd, corner->overwrite);
  corner_cmd->add_option("--seed", corner->spec.seed, "Random seed")->capture_default_str();
  corner_cmd->add_option("--noise", corner->spec.noise, "Plane noise sigma (m)")->check(CLI::Range(0.0, 10.0))->capture_default_str();
  corner_cmd->add_option("--outliers", corner->spec.outliers, "Outlier points per cloud")
      ->check(CLI::Range(0, 10000000))
      ->capture_default_str();
  corner_cmd->add_option("--points", corner->spec.points, "Points per cloud, outliers included")
      ->check(CLI::Range(3, 10000000))
      ->capture_default_str();
  corner_cmd->add_option("--angles", corner->angles, "Wall angles A:B[:STEP] in degrees (one frame each, step 10)")->capture_default_str();
  corner_cmd->add_option("--configuration", corner->spec.configuration, "Ground truth: 1 or 2 (Table 2.2), 0 random")
      ->capture_default_str();

  auto detection = std::make_shared<DetectionOptions>();
  add_detection(*sub, *detection);
  CLI::App* detection_cmd = sub->get_subcommand("detection");

  return {sub, [drive, corner, detection, drive_cmd, detection_cmd, &context] {
            if (drive_cmd->parsed()) return run_drive(*drive, context);
            if (detection_cmd->parsed()) return run_detection(*detection, context);
            return run_corner(*corner, context);
          }};
}

}  // namespace mlidar::cli
