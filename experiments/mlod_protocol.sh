#!/usr/bin/env bash
# Issue 23's protocol (thesis Table 6.2 and Fig 6.5) on simulated lyft street scenes, car class.
#   experiments/mlod_protocol.sh BUILD_DIR WORK_DIR [TRAIN_FRAMES] [TEST_FRAMES] [TRIALS] [CONFIG]
# 1. `simulate detection` train and test splits (seed 1; the splits never share a scene).
# 2. Table 6.2: single-LiDAR detectors (top, front_left, front_right; stage 1) and the three fusions (stage 1 and
#    MLOD's stage 2), each trained on the train split and run on the test split; one markdown row per case:
#    AP3D R40 at IoU 0.7 and 0.5, easy / moderate / hard, and the mean detect time per frame.
# 3. Fig 6.5: each fusion's stage 1 and MLOD, each also with online calibration first ("(OC)",
#    `--refine-extrinsics`), under extrinsic perturbation, alpha in {0, 0.02, 0.04, 0.1}, TRIALS seeds each (`detect run --alpha A --seed S`):
#    mean and standard deviation of AP3D R40 at IoU 0.7, moderate.
# Models are kept in WORK_DIR: a second run reuses them (and `--resume`s an interrupted training).
set -euo pipefail
build=${1:?BUILD_DIR}; work=${2:?WORK_DIR}
train_frames=${3:-1000}; test_frames=${4:-300}; trials=${5:-10}; config=${6:-}
mlidar="$build/apps/mlidar/mlidar"
mkdir -p "$work"
train="$work/det_train"; test="$work/det_test"
[[ -f "$train/dataset.yaml" ]] || "$mlidar" simulate detection --rig lyft --frames "$train_frames" --seed 1 --split train --out "$train" > /dev/null
[[ -f "$test/dataset.yaml" ]] || "$mlidar" simulate detection --rig lyft --frames "$test_frames" --seed 1 --split test --out "$test" > /dev/null
config_args=()
[[ -n "$config" ]] && config_args=(--config "$config")

train_model() {  # NAME STAGE ARGS...
  local name=$1 stage=$2; shift 2
  local model="$work/model-$name"
  if [[ -f "$model/model.json" ]] && jq -e ".stages | index($stage)" "$model/model.json" > /dev/null; then return; fi
  local resume=()
  [[ -f "$model/training.json" ]] && resume=(--resume)
  local stages=()
  [[ $stage == 1 ]] && stages=(--stage 1)
  "$mlidar" detect train --data "$train" "${config_args[@]}" "$@" "${stages[@]}" "${resume[@]}" --out "$model" > "$model.train.log" 2>&1
}

ap_row() {  # CASE PRED_DIR
  local json="$2/ap.json"
  "$mlidar" eval detections --gt "$test" --pred "$2" --classes car --json "$json" > /dev/null
  local cells=""
  for level in strict loose; do
    for difficulty in easy moderate hard; do
      cells+=" $(jq -r ".classes.car.$level.$difficulty.\"3d\".ap_r40 | if . == null then \"-\" else (. * 10 | round / 10 | tostring) end" "$json") |"
    done
  done
  echo "| $1 |$cells $(jq '.detect_ms.mean | . * 10 | round / 10' "$2/metrics.json") |"
}

if [[ ${OC_ONLY:-0} != 1 ]]; then
echo "| case | 0.7 easy | 0.7 mod. | 0.7 hard | 0.5 easy | 0.5 mod. | 0.5 hard | ms/frame |"
echo "|---|---|---|---|---|---|---|---|"
for lidar in top front_left front_right; do
  train_model "lidar-$lidar" 1 --fusion none --lidar "$lidar"
  pred="$work/pred-lidar-$lidar"; rm -rf "$pred"
  "$mlidar" detect run --model "$work/model-lidar-$lidar" --dataset "$test" --out "$pred" > /dev/null
  ap_row "LiDAR-$lidar" "$pred"
done
for fusion in input feature result; do
  train_model "$fusion" 2 --fusion "$fusion"
  for stage in 1 2; do
    pred="$work/pred-$fusion-stage$stage"; rm -rf "$pred"
    "$mlidar" detect run --model "$work/model-$fusion" --dataset "$test" --stage "$stage" --out "$pred" > /dev/null
    ap_row "$fusion fusion$([[ $stage == 2 ]] && echo ' + MLOD stage 2')" "$pred"
  done
done

fi

echo
echo "| case | alpha | AP3D R40 @0.7 moderate: mean | sd | trials |"
echo "|---|---|---|---|---|"
# Stage 1 alone and MLOD (both stages), each also with online calibration first (the thesis's "(OC)" rows:
# `detect run --refine-extrinsics`). OC_ONLY=1 runs only the (OC) rows (models and data as above).
for fusion in input feature result; do
  for stage in 1 2 1oc 2oc; do
    [[ ${OC_ONLY:-0} == 1 && $stage != *oc ]] && continue
    run_args=(--stage "${stage%oc}")
    [[ $stage == *oc ]] && run_args+=(--refine-extrinsics)
    for alpha in 0 0.02 0.04 0.1; do
      values=()
      for seed in $(seq 1 "$trials"); do
        pred="$work/perturbed-$fusion-$stage-$alpha-$seed"; rm -rf "$pred"
        "$mlidar" detect run --model "$work/model-$fusion" --dataset "$test" "${run_args[@]}" --alpha "$alpha" --seed "$seed" --out "$pred" > /dev/null 2>&1
        "$mlidar" eval detections --gt "$test" --pred "$pred" --classes car --json "$pred/ap.json" > /dev/null
        values+=("$(jq '.classes.car.strict.moderate."3d".ap_r40' "$pred/ap.json")")
        rm -rf "$pred/label_2"
        [[ $alpha == 0 ]] && break  # no perturbation: every trial is the same
      done
      name="$fusion stage ${stage%oc}"
      [[ $stage == 2* ]] && name="$fusion MLOD"
      [[ $stage == *oc ]] && name+=" (OC)"
      printf '%s\n' "${values[@]}" | awk -v c="$name" -v a="$alpha" \
        '{ s += $1; q += $1 * $1; n++ } END { m = s / n; v = q / n - m * m; printf "| %s | %s | %.1f | %.1f | %d |\n", c, a, m, (v > 0 ? sqrt(v) : 0), n }'
    done
  done
done
