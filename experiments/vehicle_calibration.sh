#!/usr/bin/env bash
# Issue 25's protocol (calibration on vehicles): RIG (rv or lyft) on SCENE
# (campus or street) with the `vehicle` trajectory, FRAMES frames, seeds 1..SEEDS,
# no initial guess. Per seed and auxiliary LiDAR, one markdown row for
# `calibrate auto` and one for `slam --calibrate online`: exit code, rotation /
# translation error against the simulator's truth (deg / m), NEES under the
# reported covariance (6 dof; 95 % bound 12.59), and for slam how the LiDAR
# started (translation_start, the frame of its start) and the frame and time
# (s after the first frame) of its first convergence.
# THREADS is passed to both commands (default 1).
#   experiments/vehicle_calibration.sh BUILD_DIR RIG SCENE FRAMES SEEDS WORK_DIR [THREADS]
set -euo pipefail
build=${1:?BUILD_DIR}; rig=${2:?RIG}; scene=${3:?SCENE}; frames=${4:?FRAMES}; seeds=${5:?SEEDS}; work=${6:?WORK_DIR}
threads=${7:-1}
mlidar="$build/apps/mlidar/mlidar"
mkdir -p "$work"
echo "| seed | command | LiDAR | exit | rot err deg | trans err m | NEES | start (frame) | first converged frame (s) |"
echo "|---|---|---|---|---|---|---|---|---|"
for seed in $(seq 1 "$seeds"); do
  sim="$work/$rig-$scene-$seed"
  [[ -f "$sim/dataset.yaml" ]] ||
    "$mlidar" simulate drive --rig "$rig" --scene "$scene" --trajectory vehicle --frames "$frames" --seed "$seed" --out "$sim" > /dev/null
  for command in auto slam; do
    run="$work/run-$command-$rig-$scene-$seed"
    rm -rf "$run"
    code=0
    if [[ $command == auto ]]; then
      "$mlidar" calibrate auto --dataset "$sim" --threads "$threads" --out "$run" > "$run.log" 2>&1 || code=$?
    else
      "$mlidar" slam --dataset "$sim" --threads "$threads" --out "$run" > "$run.log" 2>&1 || code=$?
    fi
    "$mlidar" eval calib --gt "$sim/groundtruth/extrinsics.yaml" --est "$run/extrinsics.yaml" --json "$run/calib.json" > /dev/null || true
    for lidar in $(jq -r '.lidars[] | select(.rotation_error_deg != 0 or .translation_error_m != 0) | .name' "$run/calib.json"); do
      rot=$(jq ".lidars[] | select(.name == \"$lidar\") | .rotation_error_deg" "$run/calib.json")
      trans=$(jq ".lidars[] | select(.name == \"$lidar\") | .translation_error_m" "$run/calib.json")
      nees=$(jq -r ".lidars[] | select(.name == \"$lidar\") | .nees | if . == null then \"-\" else (. * 100 | round / 100 | tostring) end" "$run/calib.json")
      start="-"; conv="-"
      if [[ $command == slam ]]; then
        start=$(jq -r ".per_lidar.\"$lidar\".initialization | \"\(.translation_start) (\(.frame))\"" "$run/metrics.json")
        first=$(jq ".per_lidar.\"$lidar\".first_converged_frame" "$run/metrics.json")
        conv=$(awk -v c="$first" '{ t[n++] = $1 } END { if (c == "null") print "-"; else printf "%d (%.1f)", c, t[c] - t[0] }' "$sim/times.txt")
      fi
      printf "| %s | %s | %s | %s | %.3f | %.4f | %s | %s | %s |\n" "$seed" "$command" "$lidar" "$code" "$rot" "$trans" "$nees" "$start" "$conv"
    done
  done
done
