// One or two real examples at the end of each sub-command's --help.
#include <string>
#include <utility>
#include <vector>

#include "apps/mlidar/commands.hpp"

namespace mlidar::cli {
namespace {

struct Examples {
  std::vector<std::string> path;  ///< the sub-command under `mlidar`, e.g. {"calibrate", "refine"}
  std::vector<std::string> lines;
};

const std::vector<Examples>& examples() {
  static const std::vector<Examples> all = {
      {{"info"}, {"mlidar info scan.pcd", "mlidar info frames/*.pcd --json"}},
      {{"convert"}, {"mlidar convert scan.pcd scan.ply", "mlidar convert in.ply out.pcd --encoding binary_compressed"}},
      {{"simulate", "drive"},
       {"mlidar simulate drive --rig rv --scene campus --trajectory vehicle --frames 100 --seed 1 --out sim",
        "mlidar simulate drive --rig rhd --scene room --trajectory handheld --frames 300 --perturb 5,0.1 --out room"}},
      {{"simulate", "corner"}, {"mlidar simulate corner --seed 1 --noise 0.1 --out corner"}},
      {{"simulate", "detection"},
       {"mlidar simulate detection --rig lyft --frames 500 --seed 1 --split train --out det_train",
        "mlidar simulate detection --rig lyft --frames 300 --seed 2 --split test --out det_test"}},
      {{"calibrate", "planes"},
       {"mlidar calibrate planes --ref corner/ref.pcd --target corner/target.pcd --out extrinsics.yaml --report planes.json --html "
        "planes.html"}},
      {{"calibrate", "refine"},
       {"mlidar calibrate refine --ref top.pcd --target front.pcd --init guess.yaml --out front.yaml --html front.html",
        "mlidar calibrate refine --ref top.pcd --target right.pcd --init initial_extrinsic.txt --target-id 2 --out right.yaml "
        "--report right.json"}},
      {{"calibrate", "auto"},
       {"mlidar calibrate auto --dataset sim --out calib",
        "mlidar calibrate auto --dataset sim --init guess.yaml --threads 2 --out calib"}},
      {{"odometry"},
       {"mlidar odometry --dataset sim --out run", "mlidar odometry --scans frames --times stamps.txt --config mloam.yaml --out run"}},
      {{"slam"},
       {"mlidar slam --dataset sim --out run",
        "mlidar slam --dataset sim --calibrate fixed --config config/mloam.yaml --threads 1 --out run"}},
      {{"perturb"},
       {"mlidar perturb --dataset det_test --alpha 0.04 --seed 3 --out det_test_a004",
        "mlidar perturb --dataset sim --alpha 0.1 --seed 1 --fused --out sim_perturbed"}},
      {{"detect", "train"},
       {"mlidar detect train --data det_train --config detect.yaml --fusion feature --out mlod_feature",
        "mlidar detect train --data det_train --fusion none --lidar top --stage 1 --out top_only"}},
      {{"detect", "run"},
       {"mlidar detect run --model mlod_feature --dataset det_test --out pred",
        "mlidar detect run --model mlod_feature --dataset det_test --alpha 0.04 --seed 2 --out pred_a004",
        "mlidar detect run --model mlod_feature --dataset det_test --alpha 0.04 --seed 2 --refine-extrinsics --out pred_a004_oc"}},
      {{"bag", "info"}, {"mlidar bag info drive.bag", "mlidar bag info recording_0.mcap --json"}},
      {{"bag", "export"}, {"mlidar bag export drive.bag --topics /top/points:top,/front/points:front --out dataset"}},
      {{"eval", "traj"},
       {"mlidar eval traj --gt sim/groundtruth/trajectory.tum --est run/trajectory.tum --plot run/trajectory.svg",
        "mlidar eval traj --gt sim/groundtruth/trajectory.tum --est run/trajectory.tum --out eval"}},
      {{"eval", "calib"}, {"mlidar eval calib --gt sim/groundtruth/extrinsics.yaml --est calib/extrinsics.yaml --json calib.json"}},
      {{"eval", "map"}, {"mlidar eval map --map run/map.ply --radius 0.3"}},
      {{"eval", "detections"},
       {"mlidar eval detections --gt det_test --pred detector_out --json ap.json --plot pr.svg",
        "mlidar eval detections --gt det_test/groundtruth --pred detector_out/label_2 --classes car --iou car=0.5"}},
      {{"doctor"}, {"mlidar doctor sim", "mlidar doctor drive.bag --topics /top/points:top,/front/points:front --json doctor.json"}},
      {{"fleet", "run"},
       {"mlidar fleet run --jobs jobs.yaml --out fleet --local 2",
        "mlidar fleet run --jobs /shared/fleet/jobs.yaml --out /shared/fleet/week49 --scheduler tcp://scheduler-host:8786"}},
      {{"report"}, {"mlidar report run", "mlidar report run --dataset sim --out run_with_truth.html"}},
  };
  return all;
}

}  // namespace

void add_examples(CLI::App& app) {
  for (const Examples& e : examples()) {
    CLI::App* sub = &app;
    for (const std::string& name : e.path) sub = sub->get_subcommand(name);
    std::string text = "Examples:\n";
    for (const std::string& line : e.lines) text += "  " + line + "\n";
    sub->footer(text + "\n" + sub->get_footer());
  }
}

}  // namespace mlidar::cli
