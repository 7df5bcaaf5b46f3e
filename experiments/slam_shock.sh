#!/usr/bin/env bash
# Issue 9's robustness protocol (thesis Table 4.6) end to end, online mode: the
# rhd rig (default noise) on a handheld SCENE drive of FRAMES frames; the right
# LiDAR's mounting is shifted by [10 deg, 10 deg, 10 deg, 0.1 m x 3] (mlidar's
# SE3::exp of [0.1, 0.1, 0.1, 10, 10, 10 deg]) from frame SHOCK on
# (experiments/shift_mounting.py); `mlidar slam --calibrate online` must detect
# it, re-initialize the LiDAR and re-converge to the new extrinsic. Prints the
# right LiDAR's role changes, its shock frames and its error against the
# extrinsic after the shock (and against the one before, for contrast).
# SHIFT (optional) sets another shock as "tx ty tz rx ry rz" (m, deg); CONFIG
# (optional) is passed to `mlidar slam --config`.
#   experiments/slam_shock.sh BUILD_DIR SCENE FRAMES SHOCK SEED WORK_DIR [SHIFT [CONFIG]]
set -euo pipefail
build=${1:?BUILD_DIR}; scene=${2:?SCENE}; frames=${3:?FRAMES}; shock=${4:?SHOCK}; seed=${5:?SEED}; work=${6:?WORK_DIR}
read -r -a shift_values <<< "${7:-0.1 0.1 0.1 10 10 10}"
config_args=(); [[ -n "${8:-}" ]] && config_args=(--config "$8")
mlidar="$build/apps/mlidar/mlidar"
here=$(cd "$(dirname "$0")" && pwd)
sim="$work/$scene-$seed"; run="$work/run-$scene-$seed"
rm -rf "$sim" "$run"; mkdir -p "$work"
"$mlidar" simulate drive --rig rhd --scene "$scene" --trajectory handheld --frames "$frames" --seed "$seed" --perturb 0,0 --out "$sim" > /dev/null
read -r qw qx qy qz tx ty tz < <(python3 "$here/shift_mounting.py" "$sim/scans/right" "$shock" "${shift_values[@]}")
# The extrinsic after the shock: T_base_right Delta.
python3 - "$sim/groundtruth/extrinsics.yaml" "$work/after.yaml" "$qw" "$qx" "$qy" "$qz" "$tx" "$ty" "$tz" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
head, right = text.split("  right:\n")
t = [float(v) for v in re.search(r"translation: \[([^\]]*)\]", right).group(1).split(",")]
q = [float(v) for v in re.search(r"quaternion_wxyz: \[([^\]]*)\]", right).group(1).split(",")]
dq = [float(v) for v in sys.argv[3:7]]; dt = [float(v) for v in sys.argv[7:10]]
w, x, y, z = q
R = [[1-2*(y*y+z*z), 2*(x*y-w*z), 2*(x*z+w*y)], [2*(x*y+w*z), 1-2*(x*x+z*z), 2*(y*z-w*x)], [2*(x*z-w*y), 2*(y*z+w*x), 1-2*(x*x+y*y)]]
t_new = [t[i] + sum(R[i][k] * dt[k] for k in range(3)) for i in range(3)]
a, b = q, dq
q_new = [a[0]*b[0]-a[1]*b[1]-a[2]*b[2]-a[3]*b[3], a[0]*b[1]+a[1]*b[0]+a[2]*b[3]-a[3]*b[2],
         a[0]*b[2]-a[1]*b[3]+a[2]*b[0]+a[3]*b[1], a[0]*b[3]+a[1]*b[2]-a[2]*b[1]+a[3]*b[0]]
fmt = lambda v: "[" + ", ".join(f"{c:.12g}" for c in v) + "]"
open(sys.argv[2], "w").write(head + f"  right:\n    translation: {fmt(t_new)}\n    quaternion_wxyz: {fmt(q_new)}\n")
PY
code=0; "$mlidar" slam --dataset "$sim" "${config_args[@]}" --out "$run" > "$run.log" 2>&1 || code=$?
echo "exit $code; shock at frame $shock of $frames"
jq -r '[.per_frame | to_entries[] | {k: .key, r: .value.lidars.right.role}] | . as $f
  | [range(1; length) | select($f[.].r != $f[. - 1].r) | "\($f[.].k): \($f[. - 1].r) -> \($f[.].r)"] | join(", ")
  | "right role changes: " + .' "$run/metrics.json"
jq -r '.per_lidar.right | "shock frames \(.shock_frames), restarts \(.restarts), last initialized \(.initialization.frame), last converged \(.converged_frame), accepted \(.accepted), role \(.role)"' "$run/metrics.json"
jq -r '.per_lidar.left | "left shock frames \(.shock_frames)"' "$run/metrics.json"
echo "error against the extrinsic after the shock:"
"$mlidar" eval calib --gt "$work/after.yaml" --est "$run/extrinsics.yaml" | grep right || true
echo "error against the extrinsic before the shock:"
"$mlidar" eval calib --gt "$sim/groundtruth/extrinsics.yaml" --est "$run/extrinsics.yaml" | grep right || true
