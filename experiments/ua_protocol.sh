#!/usr/bin/env bash
# Issue 19's reading of thesis Table 4.6 (sec 4.9.4): uncertainty-aware mapping
# under a wrong extrinsic, calibration off (`slam --calibrate fixed`, one thread).
# Datasets: rhd (two VLP-16) handheld through campus and room, and rv's top and
# front LiDARs (the thesis's "top-front") on a vehicle through campus; FRAMES
# frames, seeds 1..SEEDS. The auxiliary LiDAR's extrinsic is either the truth or
# the truth with the thesis's shock injected:
# R_true * Rz(10) Ry(10) Rx(10) (local) and t_true + [0.1, 0.1, 0.1] m.
# Runs per dataset, ATE RMSE (SE(3)-aligned, m) each:
#   true_wo  true extrinsics, mapping.uncertainty_aware false
#   true_ua  true extrinsics, aware, alpha = 1, the configured prior (no covariance given)
#   inj_wo   injected extrinsic, aware off
#   inj_ua   injected extrinsic given with covariance diag(0.1^2 m^2 x3, (10 deg)^2 x3), alpha = 10
#   base     the base LiDAR alone (`mlidar odometry --lidars BASE`): what ignoring the auxiliary LiDAR gives
# and the estimator's ms per frame of true_wo and true_ua.
#   experiments/ua_protocol.sh BUILD_DIR FRAMES SEEDS WORK_DIR [DATASETS (default: campus room rv)] [VOXEL_FILTER_M]
# VOXEL_FILTER_M: mapping.voxel_filter_m of the aware runs (eq 4.30; default: the configuration's).
set -euo pipefail
build=${1:?BUILD_DIR}; frames=${2:?FRAMES}; seeds=${3:?SEEDS}; work=${4:?WORK_DIR}
datasets=${5:-"campus room rv"}
voxel_filter=${6:+", voxel_filter_m: $6"}
mlidar="$build/apps/mlidar/mlidar"
mkdir -p "$work"
cat > "$work/rv_top_front.yaml" <<YAML
name: rv-top-front
base: top
base_height: 1.95
lidars:
  - {name: top, model: RS-LiDAR-16, translation: [0, 0, 0], rotation_rpy_deg: [0, 0, 0]}
  - {name: front, model: RS-LiDAR-16, translation: [0.795, 0, -1.364], rotation_rpy_deg: [0, 10, 0]}
YAML
# The given-extrinsic check (extrinsic_check, which would calibrate the injected LiDAR from the first frame) is off
# in every run: the protocol measures what the mapping does with a wrong extrinsic, calibration off.
cat > "$work/unaware.yaml" <<YAML
extrinsic_check: {residual_ratio: 0}
YAML
cat > "$work/aware_alpha1.yaml" <<YAML
mapping: {uncertainty_aware: true$voxel_filter}
extrinsic_check: {residual_ratio: 0}
YAML
cat > "$work/aware_alpha10.yaml" <<YAML
mapping: {uncertainty_aware: true$voxel_filter}
window: {extrinsic_covariance_scale: 10}
extrinsic_check: {residual_ratio: 0}
YAML

# write_extrinsics TRUTH OUT INJECT(0|1): the auxiliary LiDARs' extrinsics from the simulator's truth.
write_extrinsics() {
  python3 - "$1" "$2" "$3" <<'PY'
import math, sys, yaml
truth, out, inject = yaml.safe_load(open(sys.argv[1])), sys.argv[2], sys.argv[3] == "1"
def mul(a, b):
    w1, x1, y1, z1 = a; w2, x2, y2, z2 = b
    return [w1*w2 - x1*x2 - y1*y2 - z1*z2, w1*x2 + x1*w2 + y1*z2 - z1*y2,
            w1*y2 - x1*z2 + y1*w2 + z1*x2, w1*z2 + x1*y2 - y1*x2 + z1*w2]
def axis(i, deg):
    q = [math.cos(math.radians(deg) / 2), 0.0, 0.0, 0.0]; q[1 + i] = math.sin(math.radians(deg) / 2); return q
shock = mul(mul(axis(2, 10), axis(1, 10)), axis(0, 10))  # Rz Ry Rx: roll, pitch, yaw of 10 deg each
lidars = {}
for name, e in truth["lidars"].items():
    t, q = list(e["translation"]), list(e["quaternion_wxyz"])
    if name != truth["base"] and inject:
        t, q = [v + 0.1 for v in t], mul(q, shock)
        cov = [0.0] * 36
        for i in range(6): cov[7 * i] = 0.01 if i < 3 else math.radians(10) ** 2
        lidars[name] = {"translation": t, "quaternion_wxyz": q, "covariance": cov}
    else:
        lidars[name] = {"translation": t, "quaternion_wxyz": q}
yaml.safe_dump({"base": truth["base"], "lidars": lidars}, open(out, "w"), default_flow_style=None)
PY
}

# ATE RMSE, or nan when the run has no trajectory to align (every frame lost: the pose never moved).
ate() { if "$mlidar" eval traj --gt "$1/groundtruth/trajectory.tum" --est "$2/trajectory.tum" --json "$2/traj.json" > /dev/null 2>&1
        then jq '.ate.translation_m.rmse' "$2/traj.json"; else echo nan; fi; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a == "nan" || b == "nan") print "nan"; else printf "%.2f", a / b }'; }
ms() { jq '.total_seconds.mean * 1000' "$1/metrics.json" 2> /dev/null || jq '.seconds.total.mean * 1000' "$1/metrics.json"; }

echo "| dataset | seed | true_wo | true_ua (a=1) | inj_wo | inj_ua (a=10) | base alone | inj_ua / true_wo | true_ua / true_wo | ms true_wo / true_ua |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for dataset in $datasets; do
  case "$dataset" in
    campus|room) rig=rhd; scene=$dataset; trajectory=handheld; base=left ;;
    rv) rig="$work/rv_top_front.yaml"; scene=campus; trajectory=vehicle; base=top ;;
    *) echo "unknown dataset $dataset (campus, room, rv)" >&2; exit 2 ;;
  esac
  for seed in $(seq 1 "$seeds"); do
    sim="$work/d_${dataset}_$seed"
    if [[ ! -f "$sim/dataset.yaml" ]]; then
      "$mlidar" simulate drive --rig "$rig" --scene "$scene" --trajectory "$trajectory" --frames "$frames" --seed "$seed" \
        --encoding binary --out "$sim" > /dev/null
    fi
    write_extrinsics "$sim/groundtruth/extrinsics.yaml" "$sim/true.yaml" 0
    write_extrinsics "$sim/groundtruth/extrinsics.yaml" "$sim/inj.yaml" 1
    declare -A result=()
    for run in true_wo true_ua inj_wo inj_ua; do
      out="$work/r_${dataset}_${seed}_$run"; rm -rf "$out"
      case "$run" in
        true_wo) args=(--extrinsics "$sim/true.yaml" --config "$work/unaware.yaml") ;;
        true_ua) args=(--extrinsics "$sim/true.yaml" --config "$work/aware_alpha1.yaml") ;;
        inj_wo) args=(--extrinsics "$sim/inj.yaml" --config "$work/unaware.yaml") ;;
        inj_ua) args=(--extrinsics "$sim/inj.yaml" --config "$work/aware_alpha10.yaml") ;;
      esac
      "$mlidar" slam --dataset "$sim" --calibrate fixed --threads 1 "${args[@]}" --out "$out" > /dev/null 2>&1 || true
      result[$run]=$(ate "$sim" "$out")
    done
    out="$work/r_${dataset}_${seed}_base"; rm -rf "$out"
    "$mlidar" odometry --dataset "$sim" --lidars "$base" --threads 1 --out "$out" > /dev/null 2>&1 || true
    result[base]=$(ate "$sim" "$out")
    printf "| %s | %s | %.4f | %.4f | %.4f | %.4f | %.4f | %s | %s | %.1f / %.1f |\n" "$dataset" "$seed" \
      "${result[true_wo]}" "${result[true_ua]}" "${result[inj_wo]}" "${result[inj_ua]}" "${result[base]}" \
      "$(ratio "${result[inj_ua]}" "${result[true_wo]}")" "$(ratio "${result[true_ua]}" "${result[true_wo]}")" \
      "$(ms "$work/r_${dataset}_${seed}_true_wo")" "$(ms "$work/r_${dataset}_${seed}_true_ua")"
    unset result
  done
done
