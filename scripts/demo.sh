#!/usr/bin/env bash
# Installs dependencies, builds Release and runs mlidar's main job on the
# built-in default: a simulated drive of the thesis's four-LiDAR vehicle (rig
# rv, scene campus, trajectory vehicle, 100 frames, seed 1), then `mlidar slam`
# on it (odometry from all four LiDARs with the three others calibrated online),
# evaluated against the simulator's ground truth, with its report.html.
# Everything goes to ./mlidar_demo (or the folder given as the first argument).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:-"$PWD/mlidar_demo"}

"$root/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build" --parallel "$(nproc)" --target mlidar
mlidar="$root/build/apps/mlidar/mlidar"

mkdir -p "$out"
dataset="$out/dataset"
rm -rf "$dataset"  # the demo's own output from an earlier run
echo "== simulating the default multi-LiDAR drive into $dataset"
"$mlidar" simulate drive --rig rv --scene campus --trajectory vehicle --frames 100 --seed 1 --encoding binary_compressed \
  --out "$dataset"

echo "== what was written"
for lidar_dir in "$dataset"/scans/*/; do
  echo "  $(basename "$lidar_dir"): $(find "$lidar_dir" -name '*.pcd' | wc -l) scans"
done
echo "  times.txt: $(wc -l <"$dataset/times.txt") stamps"
echo "  ground truth: $(ls "$dataset/groundtruth" | tr '\n' ' ')"
echo "  size: $(du -sh "$dataset" | cut -f1)"
echo "== first scan of the top LiDAR"
"$mlidar" info "$dataset/scans/top/000000.pcd"

run="$out/slam"
rm -rf "$run"
echo "== M-LOAM: odometry from all four LiDARs at once, calibrating the three others online, into $run"
"$mlidar" slam --dataset "$dataset" --out "$run"
echo "== accuracy against the ground truth"
"$mlidar" eval traj --gt "$dataset/groundtruth/trajectory.tum" --est "$run/trajectory.tum" --json "$run/eval.json"
"$mlidar" eval calib --gt "$dataset/groundtruth/extrinsics.yaml" --est "$run/extrinsics.yaml" --json "$run/calib.json"
echo "== the report (open it in a browser): $run/report.html"
